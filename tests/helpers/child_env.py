"""The environment of a test's child Python process: the parent's, with folders put first on
the child's module search path through PYTHONPATH (no test edits sys.path)."""

import os


def with_python_path(*folders):
    """A copy of os.environ whose PYTHONPATH starts with ``folders`` (str or Path), then the
    parent's PYTHONPATH entries, if any."""
    entries = [str(f) for f in folders] + [e for e in os.environ.get("PYTHONPATH", "").split(
        os.pathsep) if e]
    return {**os.environ, "PYTHONPATH": os.pathsep.join(entries)}
