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


def test_one_import_package_installs_beside_the_pypi_package_systems(tmp_path):
    """pip install . puts attitude_fmu, and nothing else, at the top of site-packages: the
    PyPI package `systems` ("Describe and run systems diagrams") installs beside it and
    both import. Built from a copy of the sources, without dependencies (what is checked
    is where the files land)."""
    source = tmp_path / "source"
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(".git", "build", "dist", "*.egg-info", ".venv*",
                                                                "__pycache__", "*.nbi", "*.nbc"))
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
                          "top_level": dist.read_text("top_level.txt").split(),
                          "files": sorted({f.parts[0] for f in dist.files})}))
    """)
    out = subprocess.run([str(python), "-c", script], capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr[-3000:]
    found = __import__("json").loads(out.stdout)
    assert found["missing"] == ["blocks", "fmu_src"]
    assert "attitude_fmu" not in found["systems"] and "attitude_fmu" in found["ours"]
    assert found["top_level"] == ["attitude_fmu"]
    assert set(found["files"]) <= {"attitude_fmu", "attitude_fmu-0.1.0.dist-info", ".."}, found["files"]  # ..: bin/


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
    (blocks < systems' subpackages < fmu_src < systems.fmi, as far as each needs)."""
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
    assert "attitude_fmu.fmu_src" in edges["attitude_fmu.systems.fmi"]  # the builder reads the adapters
    assert not any(t.startswith("attitude_fmu.systems") for t in edges.get("attitude_fmu.blocks.pipeline", ()))


DOTTED = re.compile(r"(?<![\w.])((?:blocks|systems|fmu_src)(?:\.\w+)+)")
FILE_REFERENCE = re.compile(r"(?<![\w./])((?:docs|tests|fmu_src|blocks|systems)/[\w./-]+\.(?:md|py|c))")


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
