"""Cold compile of a sine-pulse batch on one thread (what a study's client compiles).

``python compile_time.py`` runs, in a child process with an empty numba cache (a temporary
NUMBA_CACHE_DIR) and NUMBA_NUM_THREADS=1, ``simulate_batch`` of two blocks under a sine pulse
(``scene_batch_trig_serial`` and the kernels it calls), and prints the CPU seconds of that call
and the kernels that took longest to compile, each without the kernels it compiled in turn.
Run it with PYTHONPATH pointing at the tree to measure.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile

CHILD = """
import json, time
from collections import defaultdict
from numba.core import event
import numpy as np

stack, own = [], defaultdict(float)

class Timer(event.Listener):
    def on_start(self, ev):
        stack.append([ev.data["dispatcher"].py_func.__qualname__, time.process_time(), 0.0])

    def on_end(self, ev):
        name, t0, inner = stack.pop()
        spent = time.process_time() - t0
        own[name] += spent - inner
        if stack:
            stack[-1][2] += spent

event.register("numba:compile", Timer())
import rockstudy as rs

t0 = time.process_time()
rs.simulate_batch(
    half_diagonal=1.0, slenderness=np.array([0.15, 0.2]), pulse="sine", amplitude=9.0, period=0.5
)
top = sorted(own.items(), key=lambda kv: -kv[1])[:8]
print(json.dumps({"total": time.process_time() - t0, "top": top}))
"""


def main():
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, NUMBA_NUM_THREADS="1")
        out = subprocess.run(
            [sys.executable, "-c", CHILD],
            env=env,
            cwd=cache,  # not the tree it is run from: PYTHONPATH chooses the tree
            capture_output=True,
            text=True,
            check=True,
        )
    result = json.loads(out.stdout.strip().splitlines()[-1])
    print(f"cold sine batch: {result['total']:.1f} CPU s")
    for name, seconds in result["top"]:
        print(f"  {seconds:6.1f} s  {name}")


if __name__ == "__main__":
    main()
