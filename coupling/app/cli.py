"""The `switchsim` command line: `switchsim run [SCENE.toml] [--out DIR] [--overwrite] [--quiet] [--plots]`,
`switchsim scene [NAME]` (a built-in scene's TOML on stdout), `switchsim plot RESULT_DIR`, `switchsim fit DATA.csv --out DIR`, `switchsim sweep`, `switchsim life`. Exit codes:
coupling/app/commands.py."""

from __future__ import annotations

import sys

if __name__ == "__main__":  # python -m coupling.app.cli: no module from the working folder (coupling/__main__.py)
    from coupling.__main__ import drop_working_folder

    drop_working_folder()

import argparse  # noqa: E402
import gc  # noqa: E402
import os  # noqa: E402


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="switchsim",
        description="Switch-contact co-simulation: impact mechanics, tribometer fits, ngspice circuit.",
    )
    sub = parser.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="run a scene (no scene: the built-in default)")
    run.add_argument("scene", nargs="?", default=None, help="scene TOML file (SI units)")
    run.add_argument("--out", default=None,
                     help="result folder (default: runs/<scene name>/; written whole, summary.json last)")
    run.add_argument("--overwrite", action="store_true",
                     help="replace a non-empty --out folder that is not a previous result of this scene")
    run.add_argument("--quiet", action="store_true", help="no progress output (the result lines stay)")
    run.add_argument("--plots", action="store_true",
                     help="also draw the PNG plots (as [output] plots = true; or later: switchsim plot DIR)")
    run.add_argument("--check", action="store_true",
                     help="rerun refined (modes, rtol, macro step, RELTOL) and with the contact gap and restitution "
                          "changed by 1 %%; report the error against the sensitivity (summary.accuracy, accuracy.png)")

    scene = sub.add_parser("scene", help="print a built-in scene's TOML, to copy and edit "
                                         "(switchsim scene default > my_relay.toml)")
    scene.add_argument("name", nargs="?", default="default",
                       help="default (the coil-driven relay), relay_force, relay_cycle or free_drop")

    plot = sub.add_parser("plot", help="draw the PNG plots of a result folder that a run wrote")
    plot.add_argument("result", help="result folder (holds summary.json)")

    fit = sub.add_parser("fit", help="fit gamma, mu(I) and R_c(F_n, I) to tribometer data")
    fit.add_argument("data", help="tribometer CSV (see docs/tribology.md for its form)")
    fit.add_argument("--out", required=True, help="output directory (created if missing; written whole)")
    fit.add_argument("--overwrite", action="store_true",
                     help="replace a non-empty --out folder that is not a previous fit of this data file")
    # --- sweep: coupling/app/sweep.py ---
    sweep = sub.add_parser("sweep", help="run a design sweep of a scene on Dask (see docs/sweeps.md)")
    sweep.add_argument("sweep", help="sweep TOML file: base scene and the parameters to vary")
    sweep.add_argument("--out", required=True, help="output directory (results/ is a Parquet dataset)")
    sweep.add_argument("--workers", type=int, default=None, help="local worker processes (default: CPUs)")
    sweep.add_argument("--scheduler", default=None, help="address of an existing Dask scheduler, tcp://host:port")
    sweep.add_argument("--resume", action="store_true", help="continue the sweep in --out; finished runs are kept")
    sweep.add_argument("--quiet", action="store_true", help="no progress output")
    # --- life: coupling/app/life.py ---
    life = sub.add_parser("life", help="electrical life: the scene's operation sampled every K operations, the "
                                       "contact worn in between (docs/contact_duty.md)")
    life.add_argument("scene", nargs="?", default=None,
                      help="scene TOML that makes and breaks once (default: the built-in relay_cycle), or a sweep "
                           "TOML: a life study per design, on Dask")
    life.add_argument("--operations", type=int, required=True, help="operations N to simulate (>= 1)")
    life.add_argument("--every", type=int, default=1, help="sample every K-th operation (default 1)")
    life.add_argument("--out", required=True, help="study folder (life.csv/.parquet, life.png, checkpoint.json)")
    life.add_argument("--resume", action="store_true", help="continue the study in --out; sampled operations are kept")
    life.add_argument("--workers", type=int, default=None, help="a sweep file's local worker processes")
    life.add_argument("--scheduler", default=None, help="a sweep file's Dask scheduler, tcp://host:port")
    life.add_argument("--quiet", action="store_true", help="no progress output")
    return parser


def main(argv: list[str] | None = None) -> int:
    # Before numpy is imported: switchsim's dense problems (finite-element modes, a few
    # hundred dof) are too small for BLAS threads, whose start alone cost 0.1-0.2 s of the
    # default run's first eigenproblem on this 2-core machine, and ten times more when it
    # is oversubscribed (docs/mechanics.md, 8.). A value the user set is kept; so are the
    # threads of a process that imported numpy before calling main().
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    args = _build_parser().parse_args(argv)
    try:
        return _command(args, one_shot=argv is None)
    finally:
        if argv is None:
            # The process's own command line (the `switchsim` script, python -m coupling.app.cli):
            # the process ends when main returns. Its objects are moved out of the cyclic
            # collector's reach, so the interpreter's teardown does not run its full
            # collections over them (~40 ms of a default run's 45 ms exit, measured with perf:
            # gc_collect_main); they are still freed as the modules are cleared. A caller
            # that passes argv (tests, scripts) keeps its collector as it was.
            gc.freeze()


def entry() -> None:
    """The process's own command line (the `switchsim` script, ``python -m coupling``): ``main``,
    and after `switchsim run` the process ends at once, its output flushed (``os._exit``).
    The interpreter's teardown then does nothing a finished run needs: it clears the modules
    and frees the run's arrays (~14 ms of the default relay's whole process, ~12 ms of the
    plunger's: bench_startup.py's "exit" phase), while every file of the result is written
    and closed, the table writer answered or killed, and the result folder's hold is the
    kernel's to release. No atexit handler is skipped that does anything here: a run
    registers logging's, which has no handler to flush. The other commands exit as usual
    (a sweep's Dask cluster, a fit's plots: libraries that may clean up at exit)."""
    code = main()
    if len(sys.argv) > 1 and sys.argv[1] == "run":
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):  # (a closed pipe: nothing more to say on it)
                pass
        os._exit(code)
    sys.exit(code)


def _command(args, *, one_shot: bool = False) -> int:
    try:
        if args.command == "run":
            from coupling.app.commands import run_command

            return run_command(args.scene, args.out, quiet=args.quiet, overwrite=args.overwrite, check=args.check,
                               plots=args.plots, one_shot=one_shot)
        if args.command == "scene":
            from coupling.core.scene import builtin_scene_text

            sys.stdout.write(builtin_scene_text(args.name))
            return 0
        if args.command == "plot":
            from coupling.app.commands import plot_command

            return plot_command(args.result)
        if args.command == "fit":
            from coupling.app.fit import fit_command

            return fit_command(args.data, args.out, overwrite=args.overwrite)
        if args.command == "sweep":
            from coupling.app.sweep import sweep_command

            return sweep_command(args.sweep, args.out, workers=args.workers, scheduler=args.scheduler,
                                 resume=args.resume, quiet=args.quiet)
        if args.command == "life":
            from coupling.app.life import life_command

            return life_command(args.scene, args.out, args.operations, args.every, resume=args.resume,
                                quiet=args.quiet, workers=args.workers, scheduler=args.scheduler)
    except (ValueError, FileNotFoundError) as err:
        # Input errors: one clear line, no traceback.
        print(f"switchsim: error: {_one_line(err)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # before the run started (loading, checking): nothing written
        print("switchsim: interrupted", file=sys.stderr)
        return 130
    except MemoryError as err:  # outside a run (a run turns its own into a failed, partial result)
        print(f"switchsim: out of memory: {_one_line(err)}", file=sys.stderr)
        return 1
    return 1


def _one_line(err: BaseException) -> str:
    """The error's text on one line: a message quoting several lines is joined, and any
    other unprintable character (a control character in a key the user wrote) is escaped."""
    text = " ".join(str(err).replace("\r\n", "\n").split("\n")).strip() or type(err).__name__
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text)


if __name__ == "__main__":
    entry()
