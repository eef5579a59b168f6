"""A side for ``epc-fast bench compare`` whose evaluate is three times as slow: run as
``python slow_python.py WORKER serve``, it makes every ``epc_fast.evaluate`` call do its work
three times, then runs the worker script. The same work again, not a spin for as long as the
call took: a spin timed by either clock came out short of its factor when other processes
shared the cores, while each repeat costs what the first call did. Three times, not twice:
a worker's first rounds after it starts can run at 1.6x the CPU time of its later ones on a
virtual machine, which a factor of two does not clear in every run."""

import runpy
import sys

import epc_fast

_evaluate = epc_fast.evaluate


def _slow_evaluate(*args, **kwargs):
    _evaluate(*args, **kwargs)
    _evaluate(*args, **kwargs)
    return _evaluate(*args, **kwargs)


epc_fast.evaluate = _slow_evaluate
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
