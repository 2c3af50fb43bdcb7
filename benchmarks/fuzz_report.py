"""Both fuzzers at full size, with their counts.

    python benchmarks/fuzz_report.py [--study-files 300] [--cli 12] [--json out.json]

(a) Record study files (tests/test_fuzz_studies.py, the record-study generator): each file is
    validated in-process as ``rockstudy validate`` does, the accepted ones run chunk by chunk
    in-process (what each dask task runs), and ``--cli`` of them, one per category, also go
    through the real ``rockstudy validate``. Counted: refused (naming the field and the
    file), succeeded (every record and sample present and ok), and the failures: traceback,
    hang (> 60 s), unclear refusal, accepted although broken, dropped (a record or sample
    missing), failed run.
(b) Public API calls (tests/test_fuzz_api.py): each must give a ValueError or TypeError
    naming its argument, or a finite answer, within 30 s. Counted: refused, answered, and the
    failures: traceback, unnamed refusal, non-finite answer, hang; each failure by category
    (the entry point).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
CLI = "import sys; from rockstudy.cli import main; sys.exit(main())"


def study_fuzz(n_files: int, n_cli: int) -> dict:
    import test_fuzz_studies as fs

    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        files, counts, by_category, failures = fs.fuzz_record_studies(Path(tmp), n_files)
        seconds = time.perf_counter() - t0
        picked = {}
        for path, cat, _ in files:
            picked.setdefault(cat.split(":")[0], path)
        paths = [str(p) for p in picked.values()][:n_cli]
        designs = sum(1 for p, _, _ in files if "[design]" in p.read_text())
        cli = subprocess.run(
            [sys.executable, "-c", CLI, "validate", *paths],
            capture_output=True,
            text=True,
            timeout=600,
        )
    return {
        "files": len(files),
        "designs": designs,
        "counts": dict(counts),
        "by_category": dict(sorted(by_category.items())),
        "failures": failures,
        "seconds": round(seconds, 1),
        "cli_files": len(paths),
        "cli_tracebacks": cli.stderr.count("Traceback"),
        "cli_exit": cli.returncode,
    }


def api_fuzz() -> dict:
    import warnings

    import test_fuzz_api as fa

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fa.warm_up()
    counts, by_category, failures = Counter(), Counter(), []
    t0 = time.perf_counter()
    for label, call, name in fa.CALLS:
        outcome, why = fa.judge(call, name, nan_documented=label.startswith(fa.NAN_DOCUMENTED))
        counts[outcome] += 1
        if why:
            by_category[f"{label.split('(')[0]}: {outcome}"] += 1
            failures.append(f"{label}: {outcome}: {why}")
    return {
        "calls": len(fa.CALLS),
        "counts": dict(counts),
        "failures_by_category": dict(sorted(by_category.items())),
        "failures": failures,
        "seconds": round(time.perf_counter() - t0, 1),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--study-files", type=int, default=300)
    parser.add_argument("--cli", type=int, default=12)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    report = {
        "studies": study_fuzz(args.study_files, args.cli),
        "api": api_fuzz(),
    }
    for part, result in report.items():
        summary = {k: v for k, v in result.items() if k != "failures"}
        print(f"{part}: {json.dumps(summary, indent=1)}")
        for line in result["failures"]:
            print(f"  {line}")
    if args.json:
        args.json.write_text(json.dumps(report, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
