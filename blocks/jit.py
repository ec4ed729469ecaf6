"""Compilation settings shared by every per-sample kernel, and where their compiled code is kept.

Without numba (an FMU's minimal environment: numpy, scipy, control) the kernels run as
the plain Python they are written in; tests prove both give the same numbers.

Compiled kernels are cached per user, in a folder keyed by the fingerprint of the sources
(KERNEL_FOLDERS of the package: their paths and contents), numba's and Python's versions,
not by where the sources are: every copy of the same sources, an installed package or each
fresh extraction of an FMU that carries them, finds what another compiled. The folder is
$ATTITUDE_FMU_CACHE, else $XDG_CACHE_HOME/attitude_fmu, else ~/.cache/attitude_fmu; where
none can be written, numba's own places are used, and NUMBA_CACHE_DIR, where set, wins. An
installed package brings the kernels of the command line's first run compiled at its build
(SHIPPED; setup.py): a folder that does not exist yet starts as a copy of them.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import sys
from pathlib import Path

try:
    import numba
    from numba import njit
except ImportError:  # pragma: no cover - exercised by the FMU's fresh-environment test
    numba = njit = None

# fast-math without the no-NaN/no-Inf assumptions: contraction to FMA, reassociation,
# reciprocal and signed-zero freedom; results stay within rounding of the plain order
FASTMATH = {"contract", "reassoc", "arcp", "nsz"}
PACKAGE_ROOT = Path(__file__).resolve().parent.parent  # attitude_fmu's folder (an FMU's resources/attitude_fmu)
KERNEL_FOLDERS = ("blocks", "systems")  # the package's folders that hold kernels, and what they import
SHIPPED = "kernel_cache"  # in an installed package: the kernels compiled ahead at its build (setup.py)


def sources_fingerprint(root: Path = PACKAGE_ROOT) -> str:
    """SHA-256 over the Python files under root's KERNEL_FOLDERS: paths (relative) and contents."""
    digest = hashlib.sha256()
    for path in sorted(p for folder in KERNEL_FOLDERS for p in (root / folder).rglob("*.py")):
        digest.update(f"{path.relative_to(root).as_posix()}\0".encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def user_cache() -> Path:
    """The project's per-user cache: $ATTITUDE_FMU_CACHE, else $XDG_CACHE_HOME/attitude_fmu,
    else ~/.cache/attitude_fmu (RuntimeError where there is no home folder)."""
    return Path(os.environ.get("ATTITUDE_FMU_CACHE") or Path(
        os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "attitude_fmu")


def cache_folder() -> Path:
    """The per-user folder of the compiled kernels of these sources."""
    version = f"numba-{numba.__version__}-py{sys.version_info[0]}{sys.version_info[1]}"
    return user_cache() / version / sources_fingerprint()[:20]


def _seed(folder: Path) -> None:
    """folder (cache_folder) made from the kernels compiled ahead at the package's build
    (PACKAGE_ROOT/kernel_cache, the same layout: systems.cli.first_run), where it has none."""
    shipped = PACKAGE_ROOT / SHIPPED / folder.parent.name / folder.name
    if folder.exists() or not shipped.is_dir():
        return
    staged = folder.with_name(f".{folder.name}.{os.getpid()}")
    shutil.copytree(shipped, staged)
    try:
        os.rename(staged, folder)  # whole or not at all; another process may have made it meanwhile
    except OSError:
        shutil.rmtree(staged, ignore_errors=True)


def _register_cache_locator() -> None:
    """Put the per-user cache (cache_folder) first among numba's cache locators, for the
    kernels of this package; numba's own locators serve every other file."""
    from numba.core import caching

    if numba.config.CACHE_DIR:
        return
    try:
        folder = cache_folder()
        _seed(folder)
    except (OSError, RuntimeError):  # no home folder, none that takes files
        return

    class SourcesCacheLocator(caching._CacheLocator):
        """Cached code of a kernel in folder, under its module's path within the package;
        fresh while the module's contents are those it was compiled from."""

        def __init__(self, py_func, py_file):
            self._py_file, self._lineno = py_file, py_func.__code__.co_firstlineno
            self._cache_path = str(folder / Path(py_file).resolve().relative_to(PACKAGE_ROOT).parent)

        def get_cache_path(self):
            return self._cache_path

        def get_source_stamp(self):
            with open(self._py_file, "rb") as fh:
                return hashlib.sha256(fh.read()).hexdigest()

        def get_disambiguator(self):
            return str(self._lineno)

        @classmethod
        def from_function(cls, py_func, py_file):
            if not Path(py_file).resolve().is_relative_to(PACKAGE_ROOT):
                return None
            locator = cls(py_func, py_file)
            try:
                locator.ensure_cache_path()
            except OSError:
                return None
            return locator

    impl = getattr(caching, "CacheImpl", None) or caching._CacheImpl
    impl._locator_classes = [SourcesCacheLocator, *impl._locator_classes]


if njit is not None:
    _register_cache_locator()


def kernel(inline: bool = False):
    """numba.njit with the project's settings, cached on disk; inline=True for inner helpers."""
    if njit is None:
        return lambda function: function
    return njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always" if inline else "never")
