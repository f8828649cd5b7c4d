"""A changeover (form C) relay: NC break and arc, transfer, NO make bounce; at release NO break and NC make bounce.

examples/changeover_relay.toml: the default relay (coil, magnet, clapper armature, card,
CuBe blade) with its blade between two fixed silver rivets: it rests preloaded (0.15 N)
on the normally-closed contact NC above it and, when the coil pulls the armature in, the
card pushes it off NC across the 0.5 mm gap onto the normally-open contact NO below. The
circuit (template "changeover"): the supply on the blade (the common), NO and NC each
switching its own load, each contact its own circuit block with its own arc.

What a relay's datasheet gives for a form C contact, from the run (summary.json's
``changeover``, ``per_contact`` and ``relay``): the NC break and its arc, the transfer time
(NC break to NO make), the NO make's bounces, the release's NO break, the transfer back
and the NC make's bounces (a datasheet's "bounce NO / NC"), and whether the contact breaks
before it makes (it does here: no instant with both throws closed; whether the NC arc
still burns when NO makes is said too). Written to --out: changeover/ (the result folder),
throws.png (each contact's current around operate and release) and example.json.

    .venv/bin/python examples/changeover_relay.py [--fast] [--out DIR]
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from coupling import load_scene, run  # noqa: E402

import example_cli  # noqa: E402  (examples/example_cli.py, next to this script)

NAME = "changeover_relay"
SCENE = Path(__file__).with_name(f"{NAME}.toml")


def plot(result, path: Path) -> None:
    """Each throw's metallic current around the operate transfer and the release transfer."""
    w = result.waveform_columns
    co = result.changeover
    names = (co["normally_open"], co["normally_closed"])
    windows = []
    if co["operate"]:
        op = co["operate"][0]
        windows.append(("operate", op["nc_break"], (op["no_make"] or op["nc_break"]) + op["no_bounce_time"] + 3e-4))
    if co["release"]:
        rel = co["release"][0]
        windows.append(("release", rel["no_break"], (rel["nc_make"] or rel["no_break"]) + (rel["nc_bounce_time"] or 0)
                        + 3e-4))
    fig, axes = plt.subplots(1, max(len(windows), 1), figsize=(11, 4), squeeze=False)
    for ax, (title, lo, hi) in zip(axes[0], windows):
        sel = (w["time"] >= lo - 2e-4) & (w["time"] <= hi)
        t = w["time"][sel] * 1e3
        for name in names:
            ax.plot(t, w[f"contact_current_{name}"][sel] + w[f"arc_current_{name}"][sel], label=f"{name} (metal + arc)")
        ax.set_title(title)
        ax.set_xlabel("time (ms)")
        ax.set_ylabel("current through the contact (A)")
        ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(fast: bool = False, out: str | Path | None = None) -> dict:
    """Run the relay (``fast`` changes nothing: the whole run takes a few seconds), write the
    result folder, the plot and example.json; return the numbers."""
    out = Path(out) if out else Path("runs/examples") / NAME
    out.mkdir(parents=True, exist_ok=True)
    result = run(load_scene(SCENE))
    result.save(out / "changeover", overwrite=True)
    plot(result, out / "throws.png")
    co = result.changeover
    per = result.contact_results
    numbers = dict(status=str(result.status), warnings=list(result.warnings), changeover=co,
                   relay={k: result.relay[k] for k in ("operate_time", "release_time")},
                   closed_intervals={name: [list(iv) for iv in result.contact_closed[name][0]] for name in per},
                   bounces={name: [op["make"]["bounces"] for op in per[name]["operations"] if "make" in op]
                            for name in per})
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def _summary(n: dict) -> str:
    co = n["changeover"]
    lines = []
    if co["operate"]:
        op = co["operate"][0]
        lines.append(f"operate: NC breaks at {op['nc_break'] * 1e3:.3f} ms (arc {op['nc_arc_duration'] * 1e3:.3f} ms), "
                     f"NO makes {co['transfer_time'] * 1e3:.3f} ms later with {op['no_bounces']} bounces over "
                     f"{op['no_bounce_time'] * 1e3:.3f} ms")
    if co["release"]:
        rel = co["release"][0]
        lines.append(f"release: NO breaks at {rel['no_break'] * 1e3:.3f} ms (arc {rel['no_arc_duration'] * 1e3:.3f} ms), "
                     f"NC makes {rel['transfer_time'] * 1e3:.3f} ms later with {rel['nc_bounces']} bounces over "
                     f"{rel['nc_bounce_time'] * 1e3:.3f} ms")
    lines.append("break before make" if co["break_before_make"] else "MAKES BEFORE IT BREAKS")
    lines += [f"warning: {w}" for w in n["warnings"]]
    return "\n".join(lines)


def cli(argv=None) -> int:
    return example_cli.run(__doc__, NAME, main, _summary, argv, fast_help="the same run (a few seconds)")


if __name__ == "__main__":
    sys.exit(cli())
