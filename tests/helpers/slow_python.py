"""A side for ``epc-fast bench compare`` whose evaluate is twice as slow: run as
``python slow_python.py WORKER serve``, it makes every ``epc_fast.evaluate`` call spin for
as long as the call took (CPU time and wall time alike), then runs the worker script."""

import runpy
import sys
import time

import epc_fast

_evaluate = epc_fast.evaluate


def _slow_evaluate(*args, **kwargs):
    start = time.perf_counter()
    result = _evaluate(*args, **kwargs)
    until = time.perf_counter() + (time.perf_counter() - start)
    while time.perf_counter() < until:
        pass
    return result


epc_fast.evaluate = _slow_evaluate
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
