"""A side for ``epc-fast bench compare`` whose evaluate is twice as slow: run as
``python slow_python.py WORKER serve``, it makes every ``epc_fast.evaluate`` call spin for
as much of the process's CPU time as the call took, then runs the worker script. CPU time,
not wall time: a spin timed by the wall clock is cut short whenever another process takes the
core, and the comparison (which times CPU) would see less than twice."""

import runpy
import sys
import time

import epc_fast

_evaluate = epc_fast.evaluate


def _slow_evaluate(*args, **kwargs):
    start = time.process_time()
    result = _evaluate(*args, **kwargs)
    until = time.process_time() + (time.process_time() - start)
    while time.process_time() < until:
        pass
    return result


epc_fast.evaluate = _slow_evaluate
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
