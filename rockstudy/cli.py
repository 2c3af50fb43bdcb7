"""The ``rockstudy`` command line."""

from __future__ import annotations

import argparse
import json
import logging
import math
import shlex
import sys
import warnings
from pathlib import Path

from . import __version__

__all__ = ["main"]


def _simulate(args) -> int:
    from . import Block, ContactWarning, StepLimitError, simulate

    if (args.half_diagonal is None) != (args.slenderness is None) or (args.width is None) != (
        args.height is None
    ):
        return _usage("give --half-diagonal with --slenderness, or --width with --height")
    if (args.half_diagonal is None) == (args.width is None):
        return _usage(
            "give the block as --half-diagonal and --slenderness, or as --width "
            "and --height (not both)"
        )
    pulse_options = [
        f"--{name.replace('_', '-')}"
        for name in ("amplitude", "period", "cycles", "pulse")
        if getattr(args, name) is not None
    ]
    if args.record and pulse_options:
        return _usage(f"--record contradicts the pulse options {', '.join(pulse_options)}")
    if not args.record and args.scale is not None:
        return _usage("--scale applies to a --record only")
    if args.width is not None:
        block = Block.from_dimensions(args.width, args.height, args.restitution)
    else:
        block = Block(args.half_diagonal, args.slenderness, args.restitution)
    motion, described = _motion(args)
    if motion is None:
        return _usage(described)
    try:
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always", ContactWarning)
            res = simulate(
                block,
                motion,
                method=args.method,
                rtol=args.rtol,
                initial_rotation=args.initial_rotation,
                initial_velocity=args.initial_velocity,
                dt_out=args.dt_out,
                friction=args.friction,
                **({} if args.max_steps is None else {"max_steps": args.max_steps}),
            )
    except StepLimitError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    for w in said:  # the contact check in one line each; other warnings as Python says them
        if issubclass(w.category, ContactWarning):
            print(f"warning: {w.message}", file=sys.stderr)
        else:
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    if args.out:
        _write_history(res, Path(args.out))
    summary = res.summary()
    impacts = res.impact_times
    summary.pop("first_impact_time", None)
    summary["impacts"] = {
        "count": int(impacts.size),
        "first": float(impacts[0]) if impacts.size else None,
        "last": float(impacts[-1]) if impacts.size else None,
    }
    summary["peaks"] = _peaks_summary(res)
    inputs = _inputs(args, block, described)
    if args.json:
        print(json.dumps({"inputs": inputs, "result": summary}, indent=2))
    else:
        for key, value in {**inputs, **summary}.items():
            print(f"{key:18s} {_text(value)}")
        if args.out:
            print(f"wrote {args.out}")
    return 0


def _motion(args):
    """(motion, what describes it) of ``rockstudy simulate``'s options: the record or the
    pulse; or (None, the usage message) for options that contradict each other."""
    from .motions import PULSES

    if args.units is not None and not args.record:
        return None, "--units applies to a --record only"
    if args.record:
        path = args.record
        if path.lower().endswith(".at2") and args.units not in (None, "g"):
            return None, f"--units {args.units}: a PEER .AT2 file is in g; leave --units out"
        motion = _read_record(path, args.units or "g")
        if args.scale is not None:
            motion = motion.scaled(args.scale)
        described = {"record": path, "units": args.units or "g"}
        described["scale"] = 1.0 if args.scale is None else args.scale
    else:
        if args.amplitude is None or args.period is None:
            return None, "a pulse needs --amplitude and --period (or give --record)"
        shape = args.pulse or "sine"
        cycles = 1 if args.cycles is None else args.cycles
        kw = {"cycles": cycles} if shape in ("sine", "cosine") else {}
        motion = PULSES[shape](args.amplitude, args.period, **kw)
        described = {"pulse": shape, "amplitude": args.amplitude, "period": args.period, **kw}
    return motion, described


def _inputs(args, block, described) -> dict:
    """The inputs of ``rockstudy simulate`` as echoed: as given, or derived."""
    return {
        "half_diagonal": _plain(block.half_diagonal, args.half_diagonal),
        "slenderness": _plain(block.slenderness, args.slenderness),
        "width": _plain(block.width, args.width),
        "height": _plain(block.height, args.height),
        "restitution": _plain(block_restitution(block), args.restitution),
        **described,
        "method": args.method,
        "rtol": args.rtol,
        **({} if args.friction is None else {"friction": args.friction}),
        "initial_rotation": args.initial_rotation,
        "initial_velocity": args.initial_velocity,
        "dt_out": args.dt_out,
    }


def _plain(value, given=None) -> float:
    """An input as the user gave it (a width of 0.45, not the 0.44999999999999996 derived
    back from R and alpha), else the derived value."""
    return float(given) if given is not None else float(value)


def _text(value) -> str:
    """A value for the text output: floats to 12 significant digits (no float noise)."""
    if isinstance(value, float):
        return f"{value:.12g}"
    return str(value)


def _read_record(path, units):
    """A record file (PEER .AT2, or two columns: time [s] and acceleration in ``units``), with
    the reader's hints in the command's terms."""
    from .motions import Record
    from .motions.records import _column_hint

    if path.lower().endswith(".at2"):
        return Record.from_at2(path)
    try:
        return Record.from_csv(path, units=units)
    except ValueError as exc:
        hint = _column_hint(("time", "horizontal"))
        message = str(exc).replace(hint, "") if hint else str(exc)
        if message != str(exc):
            message += (
                "; rockstudy simulate reads two columns, time [s] and the horizontal "
                f"acceleration in --units ({', '.join(_AccelerationUnits())})"
            )
        raise ValueError(message) from None


class _AccelerationUnits:
    """The names ``--units`` takes: the acceleration units of the package's one table of units
    (:func:`rockstudy.motions.units.acceleration_units`), read when first asked for, so that
    building the parser does not import the motions package."""

    def _names(self) -> list[str]:
        from .motions.units import acceleration_units

        return list(acceleration_units())

    def __contains__(self, name) -> bool:
        return name in self._names()

    def __iter__(self):
        return iter(self._names())


def _peaks_summary(res) -> dict:
    """The count of the peaks and the largest (by |theta|), with its time."""
    peaks = res.peak_rotations
    if peaks is None or not peaks.size:
        return {"count": 0, "largest_rotation": None, "largest_time": None}
    k = int(abs(peaks).argmax())
    return {
        "count": int(peaks.size),
        "largest_rotation": float(peaks[k]),
        "largest_time": float(res.peak_times[k]),
    }


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} is not allowed: give a whole number >= 1")
    return value


def _seconds(text: str) -> float:
    """A finite, positive number of seconds (``--timeout``)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of seconds") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"{text} is not allowed: give seconds > 0")
    return value


def _share(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"{text} is not a share in [0, 1]")
    return value


def _resume_command(args) -> str:
    words = ["rockstudy", "run", args.study, "--out", args.out, "--resume"]
    for flag in ("workers", "scheduler", "scheduler_file", "tls_ca_file", "tls_cert", "tls_key"):
        if getattr(args, flag) is not None:
            words += ["--" + flag.replace("_", "-"), str(getattr(args, flag))]
    return shlex.join(words)


def _saved(out) -> tuple[str, bool]:
    """What a stopped run kept, read from its store, and whether ``--resume`` can continue it."""
    import numpy as np

    from .study.running.store import read_marker, read_status

    try:
        if not (read_marker(out) or {}).get("template_complete"):
            raise FileNotFoundError
        status = read_status(out)
    except Exception:  # noqa: BLE001 - a store that does not open has kept nothing readable
        return f"nothing was saved in {out}", False
    return f"{np.count_nonzero(status)} of {status.size} samples are saved in {out}", True


def _stopped(args, head, advice="fix the cause, then run again") -> str:
    """The line of a run that stopped: ``head`` (ending in its separator), what was saved, and
    how to continue (the ``--resume`` command if anything was saved, else ``advice``)."""
    saved, resumable = _saved(args.out)
    if resumable:
        return f"{head}{saved}; continue with: {_resume_command(args)}"
    return f"{head}{saved}" + (f"; {advice}" if advice else "")


def _security(args):
    if not (args.tls_ca_file or args.tls_cert or args.tls_key):
        return None  # dask's configuration (distributed.comm.tls.*) applies
    from distributed.security import Security

    return Security(
        tls_ca_file=args.tls_ca_file,
        tls_client_cert=args.tls_cert,
        tls_client_key=args.tls_key,
        require_encryption=True,
    )


def _quiet_dask() -> None:
    """dask's own log lines (a lost scheduler, cancelled tasks) would bury our one line."""
    import distributed  # noqa: F401 - importing it configures the loggers quietened here

    names = [n for n in logging.root.manager.loggerDict if n.startswith("distributed.")]
    for name in ("distributed", *names):
        logging.getLogger(name).setLevel(logging.CRITICAL)


def block_restitution(block) -> float:
    """The block's coefficient of restitution (Housner's when none was given)."""
    from .structures.block import block_parameters

    return float(block_parameters(block)[2])


def _write_history(result, path: Path):
    """The history to CSV (``.csv``) or netCDF (``.nc``), by the file's suffix."""
    if path.suffix == ".csv":
        result.to_dataframe().to_csv(path, index=False)
    elif path.suffix == ".nc":
        result.to_xarray().to_netcdf(path)
    else:
        raise ValueError(f"--out must end in .csv or .nc, got {str(path)!r}")


def _np_plain_numbers() -> None:
    """Numbers in messages as numbers: numpy 2 spells a scalar ``np.float64(-13.45)`` in a
    message built with ``{value!r}``; this process spells it ``-13.45``."""
    import numpy as np

    np.set_printoptions(legacy="1.25")


def _usage(message) -> int:
    print(f"error: {message}", file=sys.stderr)
    return 2


def _run(args) -> int:
    from concurrent.futures import CancelledError

    from .study import load_study, run_study
    from .study.running.runner import FailedSamplesError, ResourceError, SchedulerError
    from .study.running.store import StoreError

    study = load_study(args.study)
    for note in study.notes:
        print(f"note: {note}", file=sys.stderr)
    _quiet_dask()
    try:
        report = run_study(
            study,
            args.out,
            workers=args.workers,
            scheduler=args.scheduler,
            scheduler_file=args.scheduler_file,
            resume=args.resume,
            base_dir=Path(args.study).resolve().parent,
            progress=not args.quiet,
            overwrite=args.overwrite,
            max_failed=args.max_failed,
            security=_security(args),
            timeout=args.timeout,
        )
    except FailedSamplesError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    except (StoreError, FileExistsError, FileNotFoundError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)  # refused: nothing was written
        return 2
    except KeyboardInterrupt:
        print("\n" + _stopped(args, "interrupted: ", None), file=sys.stderr)
        return 130
    except ResourceError as exc:  # out of memory, workers killed: kept only if resumable
        print(_stopped(args, f"error: {exc}; ", None), file=sys.stderr)
        return 1
    except SchedulerError as exc:  # the cluster was not reached: nothing ran
        print(f"error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 1
    except (OSError, CancelledError, TimeoutError) as exc:
        # disk full, read-only file system, scheduler lost
        message = " ".join(str(exc).split())  # dask's messages span lines
        print(_stopped(args, f"error: {type(exc).__name__}: {message}; "), file=sys.stderr)
        return 1
    print(
        f"{study.name}: {report.samples} samples in {report.chunks_total} chunks; computed "
        f"{len(report.chunks_computed)} chunks in {report.seconds:.1f} s"
        + (
            f" ({report.compile_seconds:.1f} s of it compiling kernels, once)"
            if report.compile_seconds
            else ""
        )
        + f"; {report.failed_samples} failed samples"
    )
    print(
        f"cube: {report.path} (xarray.open_zarr)" + (f", {report.netcdf}" if report.netcdf else "")
    )
    _contact_warning(study, report.path)
    return 0


def _contact_warning(study, path) -> None:
    """A warning on stderr when scenes lie outside the block model (a study's friction,
    under Housner's model: the contact model runs them under ``run.model`` "contact" or
    "auto")."""
    mu = study.friction_coefficients()
    if mu is None or study.run.model != "rocking":
        return
    from .study.analysis.contact import summary_line
    from .study.running.store import open_result

    line = summary_line(open_result(path).load(), mu)
    if line:
        print(f"warning: {line}; `rockstudy report` lists them", file=sys.stderr)


def _compile(args) -> int:
    """Prime numba's on-disk cache with every kernel (once per install; ``make setup``)."""
    from .study.running._warmup import main as compile_main

    return compile_main(args.group)


def _design_size(study, base_dir) -> str:
    """The folded size of a record design, as ``rockstudy validate`` prints it: records x
    floors (a list of floors) x orientations (``[design] orientations``) x structures (x
    levels of stripes); a single floor of a building is named."""
    from .study.designs.record_rows import motion_axes
    from .study.spec.design_kinds import design_kind
    from .study.spec.feasibility import record_pairs

    floors, angles = motion_axes(study)
    parts = [f"{len(record_pairs(study.motion, base_dir))} records"]
    if isinstance(getattr(study.motion, "floor", None), list):
        parts.append(f"{len(floors)} floors {floors}")
    if angles is not None:
        parts.append(f"{len(angles)} orientations")
    parts.append(f"{study.samples() // study.levels()} structures")
    if not design_kind(study.design.kind).capacities:
        parts.append(f"{study.levels()} levels")
    where = f" on floor {floors[0]}" if floors != [0] and len(floors) == 1 else ""
    return f"{study.design.kind} design{where}: " + " x ".join(parts)


def _validate(args) -> int:
    from .study import StudyError, load_study

    status = 0
    for path in args.study:
        try:
            study = load_study(path)
            size = f"{study.samples()} samples"
            if study.design is not None:
                size = _design_size(study, Path(path).resolve().parent)
            print(
                f"{path}: ok ({study.sampler.kind}, {size}, "
                f"{len(study.parameters())} distributed parameters, sha256 {study.sha256()[:12]})"
            )
            for note in study.notes:
                print(f"  note: {note}")
        except StudyError as exc:
            print(exc, file=sys.stderr)
            status = 2
    return status


class _Parser(argparse.ArgumentParser):
    """A wrong option is one line (not the usage block), exit 2."""

    def error(self, message):
        self.exit(2, f"error: {self.prog}: {message} (see {self.prog} --help)\n")


class _Help(argparse.HelpFormatter):
    """Help that shows an option's default where it has one (not None or a flag's False) and
    its text does not already say it."""

    def _get_help_string(self, action):
        text = action.help or ""
        default = action.default
        if (
            not any(default is v for v in (None, False, argparse.SUPPRESS))
            and "default" not in text
            and action.option_strings
        ):
            text += " (default: %(default)s)"
        return text


def _no_out_of_memory_traceback(record) -> bool:
    """False for a log record carrying a MemoryError (an event loop's callback of the cluster
    that ran out of memory): the command says so in its own line instead."""
    exc = record.exc_info[1] if record.exc_info else None
    return not isinstance(exc, MemoryError)


def main(argv=None) -> int:
    """Entry point of the ``rockstudy`` command: Ctrl-C at any point (also while a command's
    modules load) is one line and exit 130; zarr's IO thread is stopped before exit. A
    handler that fails to log, or an event loop's callback, out of memory in a thread of the
    cluster, prints no traceback: the command says what happened in its own line."""
    logging.raiseExceptions = False
    logging.getLogger("asyncio").addFilter(_no_out_of_memory_traceback)
    try:
        return _dispatch(_parser().parse_args(argv))
    except KeyboardInterrupt:
        print("\nrockstudy: interrupted", file=sys.stderr)
        return 130
    except (MemoryError, RuntimeError, OSError) as exc:  # outside a run: see _run for those
        from .study.running.runner import out_of_memory

        if not out_of_memory(exc):
            raise
        print(
            "error: rockstudy ran out of memory; give it more (a higher ulimit -v)", file=sys.stderr
        )
        return 1
    finally:
        if "zarr.core.sync" in sys.modules:  # else exit may print a zarr RuntimeError
            from .study.running.store import stop_zarr_io

            stop_zarr_io()


def _parser() -> argparse.ArgumentParser:
    """The parser of the ``rockstudy`` command and its subcommands."""
    parser = _Parser(
        prog="rockstudy",
        description="Rocking blocks and structures in earthquakes: simulate one, run a study "
        "file on dask, report on its results.",
        formatter_class=_Help,
    )
    parser.add_argument("--version", action="version", version=f"rockstudy {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    _add_simulate(sub)
    demo = sub.add_parser(
        "demo", help="the demo job: a plot and a JSON summary", formatter_class=_Help
    )
    demo.add_argument("--out", default="results/demo", help="directory to write")
    figs = sub.add_parser(
        "figures", help="recompute the figures of paper 000 as PNGs", formatter_class=_Help
    )
    figs.add_argument("--out", default="results/figures", help="directory to write")
    _add_run(sub)
    val = sub.add_parser(
        "validate", help="check study files, naming every problem", formatter_class=_Help
    )
    val.add_argument("study", nargs="+", help="study files (TOML)")
    sub.add_parser("schema", help="print the JSON schema of study files")
    _add_compile(sub)
    rep = sub.add_parser(
        "report",
        help="an HTML report (figures, CSV tables) of a result cube",
        formatter_class=_Help,
    )
    rep.add_argument("result", help="a zarr store (or .nc) written by 'rockstudy run'")
    rep.add_argument(
        "--out", help="directory (default: RESULT without its suffix + _report: a.zarr -> a_report)"
    )
    ver = sub.add_parser(
        "verify",
        help="check a result cube against the checksums written with it",
        formatter_class=_Help,
        description="Check a zarr cube written by 'rockstudy run': its metadata, design and "
        "every finished chunk against the sha256 recorded when they were written. Exit 0 and "
        "one line if it is intact; else one line naming the damaged variable and chunk, exit 1.",
    )
    ver.add_argument("cube", help="a zarr store written by 'rockstudy run'")
    return parser


#: The ``--method`` choices of ``rockstudy simulate``: the methods of
#: :data:`rockstudy.dynamics.methods.METHODS` that run a Block (written out here so that the
#: parser does not load numba; a test holds the two equal).
SIMULATE_METHODS = ["nonlinear", "linear", "scipy", "scipy-linear", "complex", "auto"]


def _add_compile(sub) -> None:
    """The ``compile`` command: every kernel, or the groups named."""
    comp = sub.add_parser(
        "compile", help="compile the numba kernels into their cache (once per install)"
    )
    comp.add_argument(
        "--group",
        action="append",
        choices=_COMPILE_GROUPS,
        help="only this group of kernels (repeatable; default all)",
    )


def _add_simulate(sub) -> None:
    """The ``simulate`` subcommand and its options."""
    sim = sub.add_parser(
        "simulate",
        help="rock one block through one motion",
        formatter_class=_Help,
        description="Rock one rectangular block through a pulse or a record. Units: SI "
        "(m, s, m/s^2, rad); the block as R and alpha or as width and height.",
    )
    sim.add_argument("--half-diagonal", type=float, help="R, half the diagonal [m]")
    sim.add_argument("--slenderness", type=float, help="alpha = atan(width / height) [rad]")
    sim.add_argument("--width", type=float, help="width 2b [m] (with --height)")
    sim.add_argument("--height", type=float, help="height 2h [m] (with --width)")
    sim.add_argument(
        "--restitution",
        type=float,
        default=None,
        help="eta; default: Housner's 1 - 1.5 sin^2 alpha",
    )
    sim.add_argument(
        "--pulse",
        choices=["sine", "cosine", "half-sine", "ricker"],
        help="pulse shape (default: sine)",
    )
    sim.add_argument("--amplitude", type=float, help="pulse amplitude a_g [m/s^2]")
    sim.add_argument("--period", type=float, help="pulse period T_p [s]")
    sim.add_argument("--cycles", type=int, help="cycles of a sine or cosine pulse (default: 1)")
    sim.add_argument(
        "--record",
        help="a PEER .AT2 file or a two-column file (t [s], a in --units) instead of a pulse",
    )
    sim.add_argument(
        "--units",
        choices=_AccelerationUnits(),
        help="acceleration units of a two-column --record (default: g; a .AT2 file is in g)",
    )
    sim.add_argument("--scale", type=float, help="factor on the record (default: 1)")
    sim.add_argument("--initial-rotation", type=float, default=0.0, help="theta at t = 0 [rad]")
    sim.add_argument(
        "--initial-velocity", type=float, default=0.0, help="theta_dot at t = 0 [rad/s]"
    )
    sim.add_argument(
        "--method",
        default="nonlinear",
        choices=SIMULATE_METHODS,
        help="the model and solver",
    )
    sim.add_argument("--rtol", type=float, default=1e-8, help="relative tolerance")
    sim.add_argument(
        "--friction",
        type=float,
        help="friction coefficient mu of the base, in (0, 10]: runs the contact model "
        "(slide, rock, slide-rock, flight) and reports the slide",
    )
    sim.add_argument(
        "--max-steps",
        type=_positive_int,
        help="cap on the integrator steps in one rocking phase (default 1,000,000; exceeded: "
        "exit 1)",
    )
    sim.add_argument(
        "--out",
        help="write the history to this .csv or .nc file (netCDF: with the peaks, and the "
        "--dt-out grid beside the history; CSV: the --dt-out grid instead of the history)",
    )
    sim.add_argument(
        "--dt-out",
        type=float,
        help="also give the state on the uniform grid 0, dt, 2 dt, ... [s] to the end of the "
        "response, each point as accurate as the integrator's steps (default: none)",
    )
    sim.add_argument(
        "--json", action="store_true", help="print the inputs and the outcomes as JSON"
    )


def _add_run(sub) -> None:
    """The ``run`` subcommand and its options."""
    run = sub.add_parser("run", help="run a study file into a zarr cube", formatter_class=_Help)
    run.add_argument("study", help="the study file (TOML)")
    run.add_argument("--out", required=True, help="the zarr store to write (PATH.nc too)")
    where = run.add_mutually_exclusive_group()
    where.add_argument("--workers", type=_positive_int, help="local cluster size (default 2)")
    where.add_argument("--scheduler", help="address of a running dask scheduler (tls://...)")
    where.add_argument("--scheduler-file", help="scheduler file of a running dask cluster")
    run.add_argument("--resume", action="store_true", help="compute only pending chunks")
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    run.add_argument(
        "--overwrite", action="store_true", help="let the export replace an existing OUT.nc"
    )
    run.add_argument(
        "--max-failed",
        type=_share,
        default=0.0,
        help="largest share of failed samples that still exits 0 (default 0: none)",
    )
    run.add_argument(
        "--timeout",
        type=_seconds,
        default=60.0,
        help="seconds to wait for a remote scheduler and its first worker (default 60)",
    )
    for flag, what in (("ca-file", "CA certificate"), ("cert", "client certificate")):
        run.add_argument(f"--tls-{flag}", help=f"{what} (PEM) for a tls:// scheduler")
    run.add_argument("--tls-key", help="client private key (PEM) for a tls:// scheduler")


def _verify(args) -> int:
    import time

    import zarr  # noqa: F401 - loaded before the clock starts: the time is the check's

    from .study.running.store import StoreError, verify_cube

    t0 = time.perf_counter()
    try:
        found = verify_cube(args.cube)
    except StoreError as exc:
        return _refused(exc)
    print(
        f"{args.cube}: intact: {found['done']} of {found['chunks']} chunks finished, "
        f"{found['files']} files match their sha256 ({time.perf_counter() - t0:.2f} s)"
    )
    return 0


def _report(args) -> int:
    from .study.report import make_report
    from .study.running.store import StoreError

    try:
        print(f"wrote {make_report(args.result, args.out)}")
    except StoreError as exc:
        return _refused(exc)
    return 0


def _refused(exc) -> int:
    """One line for a cube that is refused: exit 1 if it is damaged, 2 if it is not a cube."""
    from .study.running.store import DamagedCube

    print(f"error: {exc}", file=sys.stderr)
    return 1 if isinstance(exc, DamagedCube) else 2


#: The groups of ``rockstudy compile --group`` (those of ``rockstudy.study.running._warmup``,
#: written out so that the parser loads no numba; a test holds them equal).
_COMPILE_GROUPS = ("demo", "simulate", "batch-parallel", "batch-serial", "records", "closedforms")
_COMPILE_GROUPS += ("two-body",)
#: Commands that may compile numba kernels (and save them to numba's cache).
_COMPILING = ("simulate", "run", "compile", "report", "verify", "figures", "demo")


def _dispatch(args) -> int:
    """Run the command ``args.command``; a refusal is one line and exit 2."""
    _np_plain_numbers()
    if args.command in _COMPILING:  # two commands at once (`make demo`) may compile one kernel
        from ._numba_cache import serialize_cache_writes

        serialize_cache_writes()
    try:
        if args.command == "simulate":
            return _simulate(args)
        if args.command == "run":
            return _run(args)
        if args.command == "validate":
            return _validate(args)
        if args.command == "compile":
            return _compile(args)
        if args.command == "report":
            return _report(args)
        if args.command == "verify":
            return _verify(args)
        if args.command == "schema":
            from .study import json_schema

            print(json.dumps(json_schema(), indent=2))
            return 0
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
    except (ValueError, FileExistsError, FileNotFoundError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
