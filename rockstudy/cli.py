"""The ``rockstudy`` command line."""

from __future__ import annotations

import argparse
import json
import sys


def _simulate(args) -> int:
    from . import Block, simulate
    from .motions import PULSES, Record

    block = Block(args.half_diagonal, args.slenderness, args.restitution)
    if args.record:
        path = args.record
        motion = Record.from_at2(path) if path.lower().endswith(".at2") else Record.from_csv(path)
        if args.scale != 1.0:
            motion = motion.scaled(args.scale)
    else:
        if args.amplitude is None or args.period is None:
            print(
                "error: a pulse needs --amplitude and --period (or give --record)", file=sys.stderr
            )
            return 2
        cls = PULSES[args.pulse]
        kw = {"cycles": args.cycles} if args.pulse in ("sine", "cosine") else {}
        motion = cls(args.amplitude, args.period, **kw)
    res = simulate(block, motion, method=args.method, rtol=args.rtol)
    summary = res.summary()
    if args.json:
        summary["impact_times"] = res.impact_times.tolist()
        print(json.dumps(summary, indent=2))
    else:
        for key, value in summary.items():
            print(f"{key:18s} {value}")
    return 0


def main(argv=None) -> int:
    """Entry point of the ``rockstudy`` command."""
    parser = argparse.ArgumentParser(prog="rockstudy", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    sim = sub.add_parser("simulate", help="rock one block through one motion")
    sim.add_argument("--half-diagonal", type=float, required=True, help="R [m]")
    sim.add_argument("--slenderness", type=float, required=True, help="alpha [rad]")
    sim.add_argument("--restitution", type=float, default=None, help="eta (default Housner)")
    sim.add_argument("--pulse", choices=["sine", "cosine", "half-sine", "ricker"], default="sine")
    sim.add_argument("--amplitude", type=float, help="a_g [m/s^2]")
    sim.add_argument("--period", type=float, help="T_p [s]")
    sim.add_argument("--cycles", type=int, default=1)
    sim.add_argument("--record", help="a PEER .AT2 file or a two-column (t [s], a [g]) file")
    sim.add_argument("--scale", type=float, default=1.0, help="factor on the record")
    sim.add_argument(
        "--method", default="nonlinear", choices=["nonlinear", "linear", "scipy", "scipy-linear"]
    )
    sim.add_argument("--rtol", type=float, default=1e-8)
    sim.add_argument("--json", action="store_true", help="print the summary as JSON")
    demo = sub.add_parser("demo", help="the demo job: a plot and a JSON summary")
    demo.add_argument("--out", default="results/demo")
    figs = sub.add_parser("figures", help="recompute the figures of paper 000 as PNGs")
    figs.add_argument("--out", default="results/figures")
    args = parser.parse_args(argv)
    try:
        if args.command == "simulate":
            return _simulate(args)
        if args.command == "figures":
            from .figures import make_all

            for path in make_all(args.out):
                print(f"wrote {path}")
            return 0
        from .demo import run

        s = run(args.out)
        for method, r in s["results"].items():
            print(
                f"{method:10s} max|theta| = {r['max_rotation']:.6f} rad, overturned = "
                f"{r['overturned']}, impacts = {r['n_impacts']}, {r['seconds'] * 1e3:.2f} ms"
            )
        print(f"wrote {args.out}/demo.png and {args.out}/demo.json")
        return 0
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
