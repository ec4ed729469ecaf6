"""The package as a user installs it: one import name, a public API, subpackages by concern
with no import cycle, and docstrings whose cross-references resolve."""
import ast
import importlib
import re
import shutil
import subprocess
import textwrap
import venv
from pathlib import Path

import pytest

import attitude_fmu

ROOT = Path(__file__).resolve().parent.parent
PACKAGE_DIR = Path(attitude_fmu.__file__).resolve().parent
SOURCES = sorted(p for folder in ("blocks", "systems", "fmu_src") for p in (PACKAGE_DIR / folder).rglob("*.py"))


def _module(path: Path) -> str:
    parts = path.relative_to(PACKAGE_DIR).with_suffix("").parts
    return ".".join(("attitude_fmu", *(parts[:-1] if parts[-1] == "__init__" else parts)))


@pytest.mark.slow
def test_one_import_package_installs_beside_the_pypi_package_systems(tmp_path):
    """pip install . (scikit-build-core driving CMake) puts attitude_fmu, and nothing else, at
    the top of site-packages, with the compiled extension attitude_fmu._core and the native
    FMUs the build made: the PyPI package `systems` ("Describe and run systems diagrams")
    installs beside it and both import. Built from a copy of the sources, without
    dependencies (what is checked is what is built and where the files land)."""
    source = tmp_path / "source"
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(".git", "build", "built", "dist", "*.egg-info", ".venv*",
                                                                "__pycache__", "_core.*", ".*.tmp", ".ruff_cache"))
    env_dir = tmp_path / "env"
    venv.create(env_dir, with_pip=True)
    python = env_dir / "bin" / "python"
    install = subprocess.run([str(python), "-m", "pip", "install", "--quiet", "--no-deps", str(source), "systems"],
                             capture_output=True, text=True)
    assert install.returncode == 0, install.stderr[-3000:]
    script = textwrap.dedent("""
        import importlib, importlib.metadata, json
        import attitude_fmu, attitude_fmu.systems, attitude_fmu.blocks.pipeline
        from systems.parse import parse  # the PyPI package, untouched
        import systems
        missing = []
        for name in ("blocks", "fmu_src"):
            try:
                importlib.import_module(name)
            except ModuleNotFoundError:
                missing.append(name)
        dist = importlib.metadata.distribution("attitude-fmu")
        print(json.dumps({"missing": missing, "systems": systems.__file__, "ours": attitude_fmu.systems.__file__,
                          "top": sorted({f.parts[0] for f in dist.files}),
                          "files": sorted("/".join(f.parts[1:]) for f in dist.files if f.parts[0] == "attitude_fmu")}))
    """)
    out = subprocess.run([str(python), "-c", script], capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    found = __import__("json").loads(out.stdout)
    assert found["missing"] == ["blocks", "fmu_src"]
    assert "attitude_fmu" not in found["systems"] and "attitude_fmu" in found["ours"]
    assert set(found["top"]) <= {"attitude_fmu", "attitude_fmu-0.1.0.dist-info", ".."}, found["top"]  # ..: bin/
    files = found["files"]
    assert [f for f in files if f.startswith("_core.") and f.endswith((".so", ".pyd"))], files
    assert {f"built/native/{n}.fmu" for n in ("AttitudeEstimator", "ImuSensor", "MotionProfile")} <= set(files)
    assert "built/native/fmi3/AttitudeEstimator.fmu" in files and "blocks/pipeline/online.py" in files


def test_the_public_api_gives_every_name_it_lists_with_a_docstring():
    assert sorted(attitude_fmu.__all__) == sorted(set(attitude_fmu.__all__))
    for name in attitude_fmu.__all__:
        value = getattr(attitude_fmu, name)
        assert value is not None and (getattr(value, "__doc__", None) or isinstance(value, dict)), name
    assert set(attitude_fmu.__all__) <= set(dir(attitude_fmu))
    with pytest.raises(AttributeError):
        attitude_fmu.no_such_name  # noqa: B018


def test_systems_holds_subpackages_only_each_module_with_a_docstring():
    assert sorted(p.name for p in (PACKAGE_DIR / "systems").glob("*.py")) == ["__init__.py"]
    for path in SOURCES:
        assert ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))), path


def _imports(path: Path) -> set[str]:
    """attitude_fmu modules a file imports anywhere, outside `if TYPE_CHECKING:`."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").startswith("attitude_fmu"):
            found.update(f"{node.module}.{a.name}" for a in node.names)
            found.add(node.module)
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.startswith("attitude_fmu"))
    return found


def test_no_import_cycle_between_subpackages():
    """The folders form layers: every import between two of them goes one way only
    (blocks < systems' subpackages < fmu_src, as far as each needs): nothing in systems/ imports the FMUs'
    sources; the builder reads the adapters as files."""
    def package(dotted: str) -> str | None:
        """The package whose folder holds the module (or is the package) dotted names."""
        parts = dotted.split(".")[1:]
        for i in range(len(parts), -1, -1):
            folder = PACKAGE_DIR.joinpath(*parts[:i])
            if (folder / "__init__.py").is_file():
                return ".".join(["attitude_fmu", *parts[:i]])
            if i and folder.with_suffix(".py").is_file():
                return ".".join(["attitude_fmu", *parts[:i - 1]])
        return None

    edges = {}
    for path in SOURCES:
        own = package(_module(path))
        for target in filter(None, map(package, _imports(path))):
            if target != own:
                edges.setdefault(own, set()).add(target)
    state = {}

    def visit(node, trail):
        if state.get(node) == "done":
            return
        assert state.get(node) != "open", f"import cycle: {' → '.join(trail + [node])}"
        state[node] = "open"
        for target in sorted(edges.get(node, ())):
            visit(target, trail + [node])
        state[node] = "done"

    for node in sorted(edges):
        visit(node, [])
    assert not [(source, target) for source, targets in edges.items() for target in targets
                if source.startswith("attitude_fmu.systems") and target.startswith("attitude_fmu.fmu_src")]
    assert "attitude_fmu.systems.fmi.interface" in edges["attitude_fmu.fmu_src"]  # the adapters' tables
    assert not any(t.startswith("attitude_fmu.systems") for t in edges.get("attitude_fmu.blocks.pipeline", ()))


DOTTED = re.compile(r"(?<![\w.])((?:blocks|systems|fmu_src)(?:\.\w+)+)")
FILE_REFERENCE = re.compile(r"(?<![\w./])((?:docs|tests|fmu_src|blocks|systems)/[\w./-]+\.(?:md|py|cpp|c|h))(?!\w)")


def _resolves(dotted: str) -> bool:
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module("attitude_fmu." + ".".join(parts[:i]))
        except ModuleNotFoundError:
            continue
        for name in parts[i:]:
            if not hasattr(obj, name):
                return False
            obj = getattr(obj, name)
        return True
    return False


def test_every_cross_reference_in_a_docstring_resolves_inside_the_repository():
    """A dotted name (blocks.stages.heading.with_magnetometer) names a module or attribute
    of attitude_fmu; a file (docs/conventions.md) is in the repository."""
    unresolved = []
    for path in [*SOURCES, *sorted((ROOT / "tests").glob("*.py"))]:
        tree = ast.parse(path.read_text(encoding="utf-8"))
        docs = [ast.get_docstring(n) for n in ast.walk(tree)
                if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))]
        for doc in filter(None, docs):
            assert "NOTES" not in doc, f"{path}: cites a file outside the repository"
            unresolved += [f"{path.name}: {ref}" for ref in DOTTED.findall(doc) if not _resolves(ref.rstrip("."))]
            unresolved += [f"{path.name}: {ref}" for ref in FILE_REFERENCE.findall(doc)
                           if not (ROOT / ref.rstrip(".")).exists()]
    assert unresolved == []


PYTHON_FILES = sorted(p for p in ROOT.rglob("*.py") if not ({".git", "build", "built", "docs"} & set(p.relative_to(ROOT).parts))
                      and not p.relative_to(ROOT).parts[0].startswith(".venv"))


def test_no_module_imports_numba():
    """The C core is the one implementation: no module (of the package, its build or its tests)
    imports numba, and the dependencies do not name it."""
    importing = [str(p.relative_to(ROOT)) for p in PYTHON_FILES
                 if {"numba", "llvmlite"} & {name.split(".")[0] for name in _imports_of(p)}]
    assert importing == []
    assert "numba" not in (ROOT / "pyproject.toml").read_text(encoding="utf-8")


def _imports_of(path: Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module)
    return names


# a C compiler named as a program, its flags for a shared library, or the compiler Python was built with
COMPILER_CALL = re.compile(r"""["'](?:gcc|clang|cc|g\+\+|clang\+\+|-shared|-fPIC)["']|get_config_var\(\s*["']CC["']"""
                           r"""|environ(?:\.get\(|\[)\s*["']CC["']""")


def test_no_python_module_calls_a_c_compiler():
    """Every C artefact is a CMake target (CMakeLists.txt); Python drives CMake, never a
    compiler: no Python file names one, its shared-library flags or $CC."""
    calling = {str(p.relative_to(ROOT)): COMPILER_CALL.findall(p.read_text(encoding="utf-8")) for p in PYTHON_FILES
               if p != Path(__file__).resolve()}
    assert {path: found for path, found in calling.items() if found} == {}
    assert COMPILER_CALL.search('subprocess.run(["gcc", "-shared"])') and COMPILER_CALL.search('os.environ.get("CC")')
