"""A compiler and linker launcher that keeps what it builds, keyed by what decides its bits.

    compile_cache.py CACHE_DIR COMPILER ARGS...

CMake runs every compile and link of the core through it (the modules' CXX_COMPILER_LAUNCHER
and CXX_LINKER_LAUNCHER, CMakeLists.txt). scikit-build-core clears CMakeCache.txt and
CMakeFiles/ (where the objects are) whenever pip builds in a new isolated environment, which is
every `pip install .`; the cache lives beside them in the build directory
(build/<wheel tag>/compile-cache), so the README's second install reuses the first one's
objects and modules instead of compiling and linking the core again. Linking is most of the
work: the modules are optimised at link time (LTO).

A compile's key is the compiler's version and target, its arguments without the paths of the
input, the output and the dependency file and without the include directories (their headers
are in the preprocessed text), and the preprocessed translation unit without line markers
(which name the headers' paths: an isolated environment's pybind11 has a new path every time).
A hit copies the stored object; the preprocessor run that made the key has already written the
dependency file ninja reads. A link's key is the compiler's version, its arguments without the
output's path, and the bytes of every file they name (the objects, the libraries). Anything
else (no -o, several sources) runs as it is, and a cache that cannot be read or written only
costs the build.
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import tempfile
from pathlib import Path

#: Objects kept: three instruction-set levels, a few versions of each.
KEEP = 12
#: Arguments that name a path in the next argument and do not change the object's bits.
PATH_ARGS = {"-o", "-MF", "-MT", "-MQ", "-I", "-isystem", "-iquote", "-idirafter"}
#: Arguments that rename paths: their effect on the object is in the preprocessed text.
PREFIX_MAPS = ("-ffile-prefix-map=", "-fmacro-prefix-map=")
#: Arguments that only ask for the dependency file.
DEPENDENCY_ARGS = {"-MD", "-MMD"}


def _compile(command: list) -> int:
    return subprocess.call(command)


def _split(args: list):
    """(output path, source path, the arguments that enter the key) or None."""
    if "-c" not in args or args.count("-o") != 1:
        return None
    output = args[args.index("-o") + 1]
    kept, sources, skip = [], [], False
    for i, arg in enumerate(args):
        if skip:
            skip = False
            continue
        if arg in PATH_ARGS:
            skip = True
            continue
        if arg in DEPENDENCY_ARGS or arg.startswith(("-I", "-isystem") + PREFIX_MAPS):
            continue
        if not arg.startswith("-") and i > 0 and Path(arg).suffix in (".c", ".cc", ".cpp",
                                                                         ".cxx", ".C"):
            sources.append(arg)
            continue
        kept.append(arg)
    if len(sources) != 1:
        return None
    return output, sources[0], kept


def _version(compiler: str) -> bytes | None:
    done = subprocess.run([compiler, "--version", "-dumpmachine"], capture_output=True)
    return done.stdout if done.returncode == 0 else None


def _digest(parts) -> str:
    digest = hashlib.sha256()
    for part in parts:
        digest.update(hashlib.sha256(part).digest())
    return digest.hexdigest()


def _link_key(compiler: str, args: list) -> str | None:
    """A link's key, from its arguments and the bytes of the files they name."""
    version = _version(compiler)
    if version is None:
        return None
    output = args.index("-o") + 1
    kept = [arg for i, arg in enumerate(args) if i != output]
    files = [Path(arg).read_bytes() for arg in kept if not arg.startswith("-")
             and Path(arg).is_file()]
    return _digest([version, "\0".join(kept).encode(), *files])


def _key(compiler: str, args: list, kept: list, workdir: Path) -> str | None:
    """The object's key, from the preprocessed text; None when the preprocessor fails."""
    text = workdir / "unit.ii"
    pre = list(args)
    pre[pre.index("-c")] = "-E"
    pre[pre.index("-o") + 1] = str(text)
    done = subprocess.run([compiler, *pre, "-P"], capture_output=True)
    version = _version(compiler)
    if done.returncode != 0 or version is None:
        return None
    return _digest([version, "\0".join(kept).encode(), text.read_bytes()])


def _store(path: Path, data: bytes, executable: bool) -> None:
    """``data`` at ``path`` whole or not at all, with the mode the compiler gives its output."""
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=".part-")
    try:
        with os.fdopen(handle, "wb") as out:
            out.write(data)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(temporary, (0o777 if executable else 0o666) & ~umask)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def _prune(cache: Path) -> None:
    for suffix in ("*.o", "*.so"):
        kept = sorted(cache.glob(suffix), key=lambda p: p.stat().st_mtime, reverse=True)
        for old in kept[KEEP:]:
            old.unlink(missing_ok=True)


def _output_and_key(cache: Path, compiler: str, args: list):
    """(output path, key, suffix of the stored file), or None to build as it is."""
    if args.count("-o") != 1:
        return None
    if "-c" not in args:
        return args[args.index("-o") + 1], _link_key(compiler, args), ".so"
    split = _split(args)
    if split is None:
        return None
    output, _source, kept = split
    cache.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=cache) as work:
        return output, _key(compiler, args, kept, Path(work)), ".o"


def main(argv: list) -> int:
    cache, compiler, args = Path(argv[0]), argv[1], argv[2:]
    try:
        found = _output_and_key(cache, compiler, args)
    except OSError:
        found = None
    if found is None or found[1] is None:
        return _compile([compiler, *args])
    output, key, suffix = found
    stored = cache / f"{key}{suffix}"
    try:
        data = stored.read_bytes()
    except OSError:
        data = None
    if data is not None:
        _store(Path(output), data, suffix == ".so")
        os.utime(stored)  # the most recently used are the ones kept
        return 0
    status = _compile([compiler, *args])
    if status == 0:
        try:
            _store(stored, Path(output).read_bytes(), suffix == ".so")
            _prune(cache)
        except OSError:
            pass
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
