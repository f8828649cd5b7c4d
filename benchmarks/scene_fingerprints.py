"""Fingerprints of every shipped scene's results, to show that a refactor changed none.

    python benchmarks/scene_fingerprints.py --out before.json      # on the old tree
    python benchmarks/scene_fingerprints.py --out after.json       # on the new one
    python benchmarks/scene_fingerprints.py --compare before.json after.json

A fingerprint is, per scene (the built-in scenes and every examples/*.toml), the run's
status, its summary's numbers (bounce metrics, contacts, energy audit; run statistics
and timings left out) and a digest of each waveform column's bytes. ``--compare``
prints the largest relative difference per scene and "identical" where the digests
agree bit for bit. The comparison is meant for two trees on one machine.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SKIP_KEYS = {"run", "wall_time", "solver_seconds", "timing", "scene", "source"}


def _numbers(doc, path=""):
    if isinstance(doc, dict):
        for k, v in doc.items():
            if k not in SKIP_KEYS:
                yield from _numbers(v, f"{path}.{k}")
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from _numbers(v, f"{path}[{i}]")
    elif isinstance(doc, bool) or doc is None or isinstance(doc, str):
        yield path, doc
    elif isinstance(doc, (int, float)):
        yield path, float(doc)


def scenes():
    from coupling import builtin_scene, load_scene
    from coupling.core.scene import BUILTIN_SCENES

    for name in BUILTIN_SCENES:
        yield f"builtin:{name}", builtin_scene(name)
    for path in sorted((ROOT / "examples").glob("*.toml")):
        yield f"examples/{path.name}", load_scene(path)


def fingerprint(scene) -> dict:
    from coupling import run

    result = run(scene)
    out = {"status": str(result.status), "summary": dict(_numbers(result.summary))}
    if result.waveform_columns is not None:
        out["waveforms"] = {k: hashlib.sha256(v.tobytes()).hexdigest()[:16] + f" n={len(v)}"
                            for k, v in result.waveform_columns.items()}
    if result.mechanics is not None:
        m = result.mechanics
        out["mechanics_final_state"] = hashlib.sha256(m.states[-1].tobytes()).hexdigest()[:16]
    return out


def compare(a: dict, b: dict) -> int:
    changed = 0
    for name in sorted(set(a) | set(b)):
        if name not in a or name not in b:
            print(f"{name}: only in {'the first' if name in a else 'the second'}")
            changed += 1
            continue
        x, y = a[name], b[name]
        if x == y:
            print(f"{name}: identical")
            continue
        changed += 1
        worst, where = 0.0, ""
        for k in set(x["summary"]) | set(y["summary"]):
            p, q = x["summary"].get(k), y["summary"].get(k)
            if isinstance(p, float) and isinstance(q, float):
                d = 0.0 if p == q or (math.isnan(p) and math.isnan(q)) else abs(p - q) / max(abs(p), abs(q), 1e-300)
            else:
                d = 0.0 if p == q else math.inf
            if d > worst:
                worst, where = d, k
        waves = [k for k in set(x.get("waveforms", {})) | set(y.get("waveforms", {}))
                 if x.get("waveforms", {}).get(k) != y.get("waveforms", {}).get(k)]
        print(f"{name}: status {x['status']!r} -> {y['status']!r}; largest summary change {worst:.3g} at {where}; "
              f"waveform columns changed: {sorted(waves)}")
    return changed


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="write the fingerprints here (JSON)")
    ap.add_argument("--compare", nargs=2, metavar=("BEFORE", "AFTER"))
    ap.add_argument("--only", help="scene names containing this text")
    args = ap.parse_args(argv)
    if args.compare:
        a, b = (json.loads(Path(p).read_text()) for p in args.compare)
        return 1 if compare(a, b) else 0
    prints = {}
    for name, scene in scenes():
        if args.only and args.only not in name:
            continue
        print(name, file=sys.stderr, flush=True)
        prints[name] = fingerprint(scene)
    text = json.dumps(prints, indent=1, sort_keys=True)
    if args.out:
        Path(args.out).write_text(text)
    else:
        print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
