"""``epc-fast sobol``: what it writes in --out, under the scan's output policy (the indices
themselves are tested with their config in tests/scan/test_config_sobol.py)."""

import os

from epc_fast.__main__ import main
from epc_fast.scan.output import OutputLock


def test_an_out_another_run_writes_in_is_refused_naming_that_run(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    holder = OutputLock(out)
    holder.acquire()
    try:
        code = main(["sobol", "--out", str(out), "--overwrite", "--points", "16"])
    finally:
        holder.release()
    captured = capsys.readouterr()
    assert code == 2 and captured.out == "" and captured.err.count("\n") == 1
    assert captured.err.startswith(f"epc-fast sobol: error: --out '{out}': another run writes "
                                   f"here: pid {os.getpid()} on ")
    assert list(out.iterdir()) == []
