"""What `switchsim run` does: load a scene (or the default), check the destination, run,
write the result folder (the run judges itself: coupling.run), report.

Exit codes (docs/coupling.md, "Outputs"): 0 ok; 1 the run failed (what was computed is
written, status "failed ..."); 2 bad input or destination (nothing runs, nothing is
written); 3 the run finished but is physically unsound (written, status "unsound");
130 interrupted by Ctrl-C (what was computed is written, status "interrupted ...").
"""

from __future__ import annotations

import gc
import sys
from pathlib import Path

EXIT_OK, EXIT_FAILED, EXIT_INPUT, EXIT_UNSOUND, EXIT_INTERRUPTED = 0, 1, 2, 3, 130
RUNS_DIR = "runs"  # where results go without --out: runs/<scene name>/


def default_out(scene_path: str | None) -> str:
    """The result folder without --out: runs/<scene file's name without .toml>/, or
    runs/default/ for the built-in default scene (relative to the current folder)."""
    return str(Path(RUNS_DIR) / ("default" if scene_path is None else Path(scene_path).stem or "scene"))


def run_command(scene_path: str | None, out_dir: str | None, *, quiet: bool = False,
                overwrite: bool = False, check: bool = False, plots: bool = False,
                one_shot: bool = False) -> int:
    """``switchsim run`` (module docstring). ``one_shot``: the process ends when this
    returns (the command line's own process, not a caller's): the cyclic collector is off
    while the modules are imported and the scene is built, and what they made is then
    frozen (``gc.freeze``) before the run, so the run's collections never scan it."""
    # The collections cost a default run or the plunger example 10-14 ms (~110 of them,
    # bench_startup.py's phase table, gc.callbacks): most while numpy, mech, PySpice and the
    # scene are loaded (~40 000 long-lived objects, a few hundred in garbage cycles), and
    # the middle generation's, which rescanned those objects. With the start frozen:
    # 1.3-1.7 ms. Frozen objects are still freed when their last reference goes; only
    # cycles among them wait for the process's end, which is near.
    if one_shot:
        gc.disable()
    try:
        return _run(scene_path, out_dir, quiet, overwrite, check, plots, one_shot)
    finally:
        if one_shot:
            gc.enable()  # (an error before the run: the collector on again)


def _run(scene_path, out_dir, quiet, overwrite, check, plots, one_shot) -> int:
    from coupling.app.output import ResultFolder, project_matplotlib, recover, scene_identity
    from coupling.core.scene import default_scene, load_scene

    scene = default_scene() if scene_path is None else load_scene(scene_path)  # validates before running
    if plots:
        scene = scene.set("output.plots", True)
    if scene.output.plots:
        project_matplotlib()
    if out_dir is None:
        out_dir = default_out(scene_path)
    restored = recover(out_dir)  # a replacement of it killed half-way: the previous result back first
    if restored:
        _say(restored)
    folder = ResultFolder.check(out_dir, scene_identity(scene, scene_path), overwrite=overwrite)
    extra = {"scene_file": folder.identity["scene_file"]}
    writer = None
    if one_shot:  # the scene built: what exists now lives to the process's end
        gc.freeze()
        gc.enable()
        from coupling.app.table_writer import TableWriter, wanted

        if wanted(scene):  # the large tables' helper, readied while the run goes on
            writer = TableWriter.start()
            if writer is not None and scene.output.history and not check:
                from coupling.app.history_stream import HistoryStream

                writer.history = HistoryStream(writer, scene)
    try:
        return _run_and_write(scene, folder, extra, writer, quiet, check)
    finally:
        if writer is not None:
            writer.close(wait=False)  # (this process ends next: the system reaps it)


def _run_and_write(scene, folder, extra, writer, quiet, check) -> int:
    from coupling.core.master import CoupledRunError, RunInterrupted, run
    from coupling.core.results import RunStatus

    out = folder.path
    _chatter(quiet, f"running {scene.name} ({scene.kind}, t_end = {scene.t_end * 1e3:g} ms)")
    try:
        result = run(scene, progress=not quiet, check=check,
                     watch=writer.history if writer is not None else None)
    except RunInterrupted as err:
        return _write_partial(folder, err.partial, extra, f"{err}", EXIT_INTERRUPTED, writer)
    except CoupledRunError as err:
        return _write_partial(folder, err.partial, extra, f"{err}", EXIT_FAILED, writer)
    try:
        folder.write(result, extra, writer)
    except KeyboardInterrupt:
        _say(f"interrupted while writing the result; {out} was left as it was")
        return EXIT_INTERRUPTED
    except OSError as err:
        _say(f"could not write the result into {out}: {err.strerror or err}; {out} was left as it was")
        return EXIT_FAILED
    except Exception as err:  # noqa: BLE001 - a fault while writing is not bad input (exit 2)
        _say(f"could not write the result into {out}: {type(err).__name__}: {' '.join(str(err).split())}; "
             f"{out} was left as it was")
        return EXIT_FAILED
    _result_lines(result.summary)
    for note in folder.notes:
        _say(note)
    for problem in result.problems:
        _say(f"unsound: {problem}")
    _say(f"status {result.status}; wrote {out}")
    return EXIT_UNSOUND if result.status is RunStatus.UNSOUND else EXIT_OK


def plot_command(result_dir: str) -> int:
    """Draw the PNG plots of a result folder into it (each file written whole, by rename)."""
    import json

    from coupling.app.output import project_matplotlib, recover

    restored = recover(result_dir)
    if restored:
        _say(restored)
    folder = Path(result_dir)
    summary = folder / "summary.json"
    if not summary.is_file():
        _say(f"error: {result_dir!r} holds no summary.json: give a folder that `switchsim run` wrote")
        return EXIT_INPUT
    try:
        doc = json.loads(summary.read_bytes())
    except OSError as err:
        _say(f"error: {summary}: cannot be read: {err.strerror or err}")
        return EXIT_INPUT
    except (ValueError, RecursionError) as err:  # truncated or not JSON
        _say(f"error: {summary}: not a switchsim summary (not valid JSON: {' '.join(str(err).split())}); "
             "the result is damaged: run the scene again")
        return EXIT_INPUT
    if not isinstance(doc, dict):
        _say(f"error: {summary}: not a switchsim summary (a JSON {type(doc).__name__}, not an object)")
        return EXIT_INPUT
    project_matplotlib()
    from coupling.app.plots import save_plots, stored_result

    try:
        stored = stored_result(folder)
    except OSError as err:
        _say(f"error: {result_dir}: the result's files cannot be read: {err.strerror or err}")
        return EXIT_INPUT
    except Exception as err:  # noqa: BLE001 - a damaged table of the result: one line, not a traceback
        _say(f"error: {result_dir}: the result's files cannot be read back ({type(err).__name__}: "
             f"{' '.join(str(err).split())[:200]}); the result is damaged: run the scene again")
        return EXIT_INPUT
    try:
        paths = save_plots(stored, folder)
    except OSError as err:
        _say(f"could not draw into {folder}: {err.strerror or err}")
        return EXIT_FAILED
    except Exception as err:  # noqa: BLE001 - a table that reads but cannot be drawn: one line
        _say(f"could not draw the plots of {folder}: {type(err).__name__}: {' '.join(str(err).split())[:200]}")
        return EXIT_FAILED
    _say(f"wrote {', '.join(p.name for p in paths) or 'no plots (the folder has no waveforms or history)'} "
         f"into {folder}")
    return EXIT_OK


def _write_partial(folder, partial, extra: dict, message: str, code: int, writer=None) -> int:
    message = " ".join(message.split())  # one line, whatever the cause quotes
    if partial is None:
        _say(f"{message}; nothing could be kept, nothing written")
        return code
    try:
        folder.write(partial, extra, writer)
    except KeyboardInterrupt:
        _say(f"{message}; interrupted again while writing: nothing written")
        return EXIT_INTERRUPTED
    except Exception as err:  # noqa: BLE001 - OSError (disk full) or a fault in a table or plot
        _say(f"{message}; the partial result could not be written: {type(err).__name__}: "
             f"{' '.join(str(getattr(err, 'strerror', None) or err).split())}")
        return code
    _say(f"{message}; what was computed is in {folder.path} (status {partial.status.value!r})")
    return code


def _armature_part(relay: dict, armature: dict) -> str:
    """The relay line's armature: its first arrival at the pole, how often it rebounded and
    when it last arrived (the default relay's armature rebounds on the pole for 3 ms), and
    when it left (the release, or, with a warning of its own, while the coil was on)."""
    if relay.get("armature_arrival") is None:
        return "armature never at the pole"
    text = f"armature at the pole {_ms(relay['armature_arrival'])}"
    bounces, last, left = armature.get("pole_bounces"), armature.get("last_arrival"), armature.get("left_pole")
    if bounces and last is not None:
        text += f" ({bounces} rebound(s), last arrival {_ms(last)})"
    if left is not None:
        text += f", left it {_ms(left)}"
    return text


def _result_lines(summary: dict) -> None:
    """The results (kept with --quiet): stdout, one line each."""
    if "bounce" in summary:
        b = summary["bounce"]
        peak = b.get("peak_contact_voltage")
        settle = (f"settled closed {_ms(b['settle_time'])} after the first make" if b.get("settled")
                  else b.get("settle_note") or f"final state {b.get('final_state')}")
        held = next((op["held"] for op in summary.get("operations") or () if "force" in op.get("held", {})), None)
        if held is not None:  # the first held closure: the datasheet's contact force and resistance
            settle += f", held at {held['force']:.3g} N" + (
                f" (R_c {held['contact_resistance'] * 1e3:.3g} mohm)" if held.get("contact_resistance") else "")
        print(f"switchsim: first make {_ms(b.get('first_make'))}, last make {_ms(b.get('last_make'))}, "
              f"{b.get('bounces')} bounce(s), {settle}, "
              f"peak contact voltage {'none (no opening)' if peak is None else f'{peak:.3g} V'}, "
              f"arc energy {b.get('arc_energy') or 0:.3g} J")
    relay = summary.get("relay")
    if relay:
        parts = [f"operate time {_ms(relay['operate_time'])}" if relay.get("operate_time") is not None else None,
                 f"release time {_ms(relay['release_time'])}" if relay.get("release_time") is not None else None,
                 _armature_part(relay, summary.get("armature") or {}),
                 f"pull-in at {relay['pull_in_current'] * 1e3:.4g} mA" if relay.get("pull_in_current") is not None
                 else None]
        energy = relay.get("energy") or {}
        if energy.get("relative_residual") is not None:
            parts.append(f"coil energy residual {energy['relative_residual']:.2g}")
        if energy.get("interface_relative_residual") is not None:
            parts.append(f"coil-armature interface {energy['interface_relative_residual']:.2g}")
        print("switchsim: relay: " + ", ".join(p for p in parts if p))
    co = summary.get("changeover")
    if co:  # coupling.core.arrangement.changeover_metrics
        no, nc = co["normally_open"], co["normally_closed"]
        parts = [f"transfer time {_ms(co['transfer_time'])}" if co.get("transfer_time") is not None else
                 f"{no} never made after {nc} broke"]
        if co["operate"] and co["operate"][0].get("no_bounces") is not None:
            parts.append(f"{no} make {co['operate'][0]['no_bounces']} bounce(s)")
        if co["release"] and co["release"][0].get("nc_bounces") is not None:
            parts.append(f"release transfer {_ms(co['release_transfer_time'])}, {nc} make "
                         f"{co['release'][0]['nc_bounces']} bounce(s)")
        parts.append({True: "break before make", False: "MAKES BEFORE IT BREAKS", None: "no transfer"}[
            co.get("break_before_make")])
        print("switchsim: changeover: " + ", ".join(parts))
    if "contacts" in summary and not (relay and not summary["contacts"]):  # (an actuator alone has no contact)
        residual = summary.get("energy", {}).get("relative_residual")
        e = summary.get("restitution") or {}
        first = ", ".join(f"{v:.3g} ({k})" for k, v in e.items() if v is not None) or "none (no rebound)"
        print(f"switchsim: {len(summary['contacts'])} contact(s), first restitution {first}, "
              f"energy residual {residual if residual is None else f'{residual:.2g}'}")
    for flag in summary.get("flags", []):
        print(f"switchsim: flag: {flag}")
    for line in summary.get("warnings", []):  # coupling.core.diagnostics
        print(f"switchsim: warning: {line}")
    if "accuracy" in summary:  # --check
        print(f"switchsim: accuracy: {summary['accuracy']['verdict']}")
        for name, own in summary["accuracy"].get("per_contact", {}).items():
            print(f"switchsim: accuracy of contact {name}: {own['verdict']}")
    sys.stdout.flush()


def _chatter(quiet: bool, text: str) -> None:
    """Progress and bookkeeping lines: stderr, dropped by --quiet."""
    if not quiet:
        print(f"switchsim: {text}", file=sys.stderr, flush=True)


def _say(text: str) -> None:
    """Outcome lines (failures, unsoundness, where the result is): stderr, always."""
    print(f"switchsim: {text}", file=sys.stderr, flush=True)


def _ms(value) -> str:
    return "none" if value is None else f"{value * 1e3:.4f} ms"
