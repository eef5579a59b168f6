"""The layout's rules that more than one test file checks: the shared prefix of file names that
stands for a subsystem (the package's modules, the core's headers)."""

from collections import Counter


def shared_prefixes(names) -> dict:
    """{first word: count} of the module names (``optimize_config``: ``optimize``) that two or
    more of ``names`` share, the bare word (``optimize``) counted too."""
    names = [name for name in names if not name.startswith("_")]
    prefixes = Counter(name.split("_")[0] for name in names if "_" in name)
    return {prefix: count + (prefix in names) for prefix, count in prefixes.items()
            if count + (prefix in names) > 1}
