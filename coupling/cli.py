"""The `switchsim` command line: `switchsim run [SCENE.toml] --out DIR`, `switchsim fit DATA.csv --out DIR`."""

from __future__ import annotations

import argparse
import sys


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="switchsim",
        description="Switch-contact co-simulation: impact mechanics, tribometer fits, ngspice circuit.",
    )
    sub = parser.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="run a scene (no scene: the built-in default)")
    run.add_argument("scene", nargs="?", default=None, help="scene TOML file (SI units)")
    run.add_argument("--out", required=True, help="output directory (created if missing)")
    run.add_argument("--quiet", action="store_true", help="no progress output")
    run.add_argument("--check", action="store_true",
                     help="rerun refined (modes, rtol, macro step, RELTOL) and report the error (summary.accuracy)")

    fit = sub.add_parser("fit", help="fit gamma, mu(I) and R_c(F_n, I) to tribometer data")
    fit.add_argument("data", help="tribometer CSV (see docs/tribology.md for its form)")
    fit.add_argument("--out", required=True, help="output directory (created if missing)")
    return parser


def main(argv: list[str] | None = None) -> int:
    args = _build_parser().parse_args(argv)
    try:
        if args.command == "run":
            from coupling.commands import run_command

            return run_command(args.scene, args.out, quiet=args.quiet, check=args.check)
        if args.command == "fit":
            from coupling.tribology.command import fit_command

            return fit_command(args.data, args.out)
    except (ValueError, FileNotFoundError) as err:
        # Input errors: one clear line, no traceback.
        print(f"switchsim: error: {err}", file=sys.stderr)
        return 2
    return 1


if __name__ == "__main__":
    sys.exit(main())
