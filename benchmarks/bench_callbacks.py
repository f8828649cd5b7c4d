"""Benchmark: ngspice's compiled source callbacks against its Python callbacks, in one process.

    .venv/bin/python benchmarks/bench_callbacks.py [--repeat 21] [scene.toml ...]

Runs each scene (default: the built-in default relay) through ``coupling.run`` once to warm
up, then ``--repeat`` times through each route in alternation (SWITCHSIM_PYTHON_CALLBACKS
unset, then "1": the route is chosen at each circuit load), and prints the CPU time
(time.process_time: less moved by other processes on a shared machine than the wall
clock) per run, min and median, and the number of calls ngspice made into Python on each
route. Both routes give the same results to the bit (tests/circuit/test_compiled_callbacks_runs.py);
this measures only what the C callbacks save. Prints; writes nothing.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import statistics
import subprocess
import sys
import time

ROUTES = (("compiled", None), ("python", "1"))


def python_calls(path: str | None) -> dict[str, int]:
    """ngspice's calls into Python in one run of the scene per route, counted in a fresh
    process (the session's callbacks are wrapped before it is created)."""
    done = subprocess.run([sys.executable, __file__, "--count", *([path] if path else [])], check=True,
                          capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def _count(path: str | None) -> None:
    import circuit.ngspice as ngspice
    from coupling import load_scene, run
    from coupling.core.scene import default_scene

    scene = load_scene(path) if path else default_scene()

    counts: collections.Counter = collections.Counter()
    names = ("_on_vsrc", "_on_isrc", "_on_sync", "_on_data", "_on_c_evaluate", "_on_c_learn", "_on_c_learn_arc",
             "_on_sync_from_c")
    originals = {name: getattr(ngspice.NgspiceSession, name) for name in names}

    def counted(name):
        inner = originals[name]

        def wrapper(self, *args):
            counts[name] += 1
            return inner(self, *args)
        return wrapper

    for name in names:
        setattr(ngspice.NgspiceSession, name, counted(name))
    out = {}
    for route, value in ROUTES:
        _set_route(value)
        counts.clear()
        run(scene)
        # (on the compiled route _on_sync runs inside _on_sync_from_c, the entry from C)
        out[route] = sum(counts.values()) - (counts["_on_sync"] if route == "compiled" else 0)
    print(json.dumps(out))


def _set_route(value: str | None) -> None:
    if value is None:
        os.environ.pop("SWITCHSIM_PYTHON_CALLBACKS", None)
    else:
        os.environ["SWITCHSIM_PYTHON_CALLBACKS"] = value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", help="scene files (default: the built-in default relay)")
    parser.add_argument("--repeat", type=int, default=21)
    parser.add_argument("--count", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.count:
        return _count(args.scenes[0] if args.scenes else None)
    from circuit import compiled_callbacks
    from coupling import load_scene, run
    from coupling.core.scene import default_scene

    if compiled_callbacks.load() is None:
        raise SystemExit("the compiled callbacks are not available here (see the note above)")
    saved = os.environ.get("SWITCHSIM_PYTHON_CALLBACKS")
    try:
        paths = args.scenes or [None]
        for path in paths:
            label, scene = ("default", default_scene()) if path is None else (os.path.basename(path), load_scene(path))
            calls = python_calls(path)
            run(scene)  # (warm-up)
            times: dict[str, list[float]] = {route: [] for route, _ in ROUTES}
            for _ in range(args.repeat):
                for route, value in ROUTES:
                    _set_route(value)
                    tick = time.process_time()
                    run(scene)
                    times[route].append(time.process_time() - tick)
            print(f"{label} (CPU time per run, {args.repeat} runs per route, alternating):")
            for route, _ in ROUTES:
                series = times[route]
                print(f"  {route:9s} min {min(series) * 1e3:7.1f} ms  median {statistics.median(series) * 1e3:7.1f} ms"
                      f"  calls into Python {calls[route]}")
    finally:
        _set_route(saved)


if __name__ == "__main__":
    main()
