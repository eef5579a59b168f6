"""``--ref GIT_REF``: a commit of a git checkout built into a venv, once, and kept.

The commit's tree (``git archive``, so that neither the work tree nor its build folders take
part) is unpacked into a temporary folder and installed with pip into
``$XDG_CACHE_HOME/epc_fast/bench-ref/<commit>/venv`` (default ``~/.cache``), which later runs
with the same commit reuse: the build takes minutes, a cached baseline nothing. A venv is only
kept once its install has finished (it is built under another name and renamed), so an
interrupted build is never taken for a finished one.
"""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path


def cache_root() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "epc_fast" / "bench-ref"


def resolve(repo: Path, ref: str) -> str:
    """The full commit id ``ref`` names in ``repo``; a UsageError naming both when it names
    none."""
    from ..jobs.errors import UsageError

    try:
        out = subprocess.run(["git", "-C", str(repo), "rev-parse", "--verify", "--quiet",
                              f"{ref}^{{commit}}"], capture_output=True, text=True, check=False)
    except OSError as exc:
        raise UsageError(f"--ref {ref!r}: git cannot run ({exc})") from None
    commit = out.stdout.strip()
    if out.returncode != 0 or not commit:
        raise UsageError(f"--ref {ref!r}: not a commit of the git checkout --repo {str(repo)!r}")
    return commit


def _python(venv: Path) -> Path:
    return venv / "bin" / "python"


def ref_python(repo: Path, ref: str, progress=print) -> str:
    """The command line of the cached venv's Python for ``ref`` (built first when missing),
    with PYTHONPATH unset so that it imports its own epc_fast."""
    commit = resolve(repo, ref)
    home = cache_root() / commit
    venv = home / "venv"
    if not _python(venv).exists():
        progress(f"--ref {ref}: building commit {commit[:12]} into {venv} (minutes, once)")
        home.mkdir(parents=True, exist_ok=True)
        partial = home / "venv.partial"
        shutil.rmtree(partial, ignore_errors=True)
        with tempfile.TemporaryDirectory(prefix="epc-fast-ref-") as tmp:
            archive = subprocess.run(["git", "-C", str(repo), "archive", "--format=tar", commit],
                                     capture_output=True, check=True).stdout
            subprocess.run(["tar", "-x", "-C", tmp], input=archive, check=True)
            subprocess.run([sys.executable, "-m", "venv", str(partial)], check=True)
            env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
            subprocess.run([str(_python(partial)), "-m", "pip", "install", "--quiet", tmp],
                           check=True, env=env)
        partial.rename(venv)
    else:
        progress(f"--ref {ref}: commit {commit[:12]}, cached in {venv}")
    return f"env -u PYTHONPATH {shlex.quote(str(_python(venv)))}"
