"""Refusals in one line (issue 50, point 6): `attitude export FILE.py:NAME` where the file or NAME fails
(exit 2, the status of bad input, not 1, that of a missed bound), and cosimulate on SSPs that are broken or
that name components outside themselves (never loaded), leaving no extraction folder."""
import math
import tempfile
import zipfile

import pytest
from lxml import etree

from attitude_fmu.systems.cli.commands import main
from attitude_fmu.systems.fmi.cosim import MAX_STEPS, cosimulate
from attitude_fmu.systems.fmi.verify import write_verify_ssp

SSD = "{http://ssp-standard.org/SSP1/SystemStructureDescription}"


@pytest.mark.parametrize("code, message", [
    ("def plant():\n    raise RuntimeError('no plant today')\n",
     "plant() in {file} failed: RuntimeError: no plant today"),
    ("def plant(order):\n    return order\n",
     "plant() in {file} failed: TypeError: plant() missing 1 required positional argument: 'order'"),
    ("import a_module_nobody_wrote\n",
     "{file} failed to run: ModuleNotFoundError: No module named 'a_module_nobody_wrote'"),
    ("import sys\nsys.exit(0)\n",
     "{file} failed to run: it called sys.exit(0); a file given to export defines the system without ending "
     "the program"),
    ("raise SystemExit('bye')\n", "{file} failed to run: it called sys.exit('bye')"),
    ("def plant(:\n", "{file} failed to run: SyntaxError"),
    ("plant = 3\n", "{spec} is a int, not a python-control system"),
], ids=["raises", "needs-arguments", "import-fails", "exit-0", "exit-text", "syntax", "not-a-system"])
def test_export_refuses_a_failing_source_in_one_line_with_exit_2(tmp_path, capsys, code, message):
    file = tmp_path / "plant.py"
    file.write_text(code)
    out = tmp_path / "plant.fmu"
    assert main(["export", f"{file}:plant", "--out", str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1 and "Traceback" not in captured.err, captured.err
    assert captured.err.startswith("attitude: error: " + message.format(file=file, spec=f"{file}:plant")), \
        captured.err
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["plant.py"]


def test_export_refuses_a_model_identifier_too_long_for_a_file_name(tmp_path, capsys):
    (tmp_path / "plant.py").write_text("import control\nplant = control.ss([[0.5]], [[1.0]], [[2.0]], [[0.0]], 0.1)\n")
    assert main(["export", f"{tmp_path / 'plant.py'}:plant", "--out", str(tmp_path / "p.fmu"), "--name",
                 "a" * 300]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "has 300 characters; its files' names take 200 at most" in err, err


# cosimulate


@pytest.fixture(scope="module")
def ssp(fmu_dir, tmp_path_factory):
    """verify's SSP of incline × wiener (native FMUs), written once."""
    return write_verify_ssp(tmp_path_factory.mktemp("ssp") / "incline.ssp", fmu_dir, "incline", "wiener")


@pytest.fixture
def no_leftovers(tmp_path, monkeypatch):
    """A temporary folder of the test's own for cosimulate's extraction: empty after the test."""
    folder = tmp_path / "extracted"
    folder.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(folder))
    yield folder
    assert list(folder.iterdir()) == []


def _rewritten(ssp, path, source=None, extra=None):
    """ssp copied to path, the first component's source replaced by source, extra (name → bytes) added."""
    with zipfile.ZipFile(ssp) as src, zipfile.ZipFile(path, "w") as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "SystemStructure.ssd" and source is not None:
                root = etree.fromstring(data)
                root.find(f".//{SSD}Component").set("source", source)
                data = etree.tostring(root, xml_declaration=True, encoding="UTF-8")
            dst.writestr(item.filename, data)
        for name, data in (extra or {}).items():
            dst.writestr(name, data)
    return path


@pytest.mark.parametrize("stop, step, message", [
    (1.0, 0.0, "the step size must be a finite positive number of seconds, got 0.0"),
    (math.inf, 0.01, "the stop time must be a finite positive number of seconds, got inf"),
    (math.nan, 0.01, "the stop time must be a finite positive number of seconds, got nan"),
    (-1.0, 0.01, "the stop time must be a finite positive number"),
    (1.0, -0.01, "the step size must be a finite positive number"),
    (1e-5, 0.01, "makes 0 steps; cosimulate runs 1 to"),
    (1e6, 1e-3, f"makes 1000000000 steps; cosimulate runs 1 to {MAX_STEPS}"),
    ("1", 0.01, "the stop time must be a finite positive number of seconds, got '1'"),
], ids=["step-0", "stop-inf", "stop-nan", "stop-negative", "step-negative", "no-step", "too-many", "text"])
def test_cosimulate_refuses_times_before_reading_anything(tmp_path, no_leftovers, stop, step, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(".", r"\.")):
        cosimulate(tmp_path / "absent.ssp", stop, step)


def test_cosimulate_refuses_what_is_no_ssp(tmp_path, no_leftovers):
    (tmp_path / "text.ssp").write_text("not a zip")
    with zipfile.ZipFile(tmp_path / "empty.ssp", "w") as zf:
        zf.writestr("readme.txt", "no SystemStructure.ssd")
    (tmp_path / "bad.ssp").write_bytes(b"")
    with zipfile.ZipFile(tmp_path / "bad.ssp", "w") as zf:
        zf.writestr("SystemStructure.ssd", "<not-ssd/>")
    for name, message in (("text.ssp", "BadZipFile"), ("empty.ssp", "KeyError"), ("bad.ssp", "")):
        with pytest.raises(ValueError, match=f"{name} is no SSP fmpy can read: .*{message}") as raised:
            cosimulate(tmp_path / name, 1.0, 0.01)
        assert "\n" not in str(raised.value)
    with pytest.raises(ValueError, match="absent.ssp is no SSP fmpy can read: FileNotFoundError"):
        cosimulate(tmp_path / "absent.ssp", 1.0, 0.01)


@pytest.mark.parametrize("where", ["parent", "absolute", "deep"])
def test_a_component_outside_the_ssp_is_refused_and_never_loaded(ssp, tmp_path, no_leftovers, where):
    """A source leaving the SSP (../, absolute, through a folder of its own): refused by name; the FMU there,
    which the former master loaded and ran, is not even opened."""
    outside = tmp_path / "outside.fmu"
    outside.write_bytes(b"")  # an FMU fmpy would fail to read: reaching it at all would raise another error
    source = {"parent": "../outside.fmu", "absolute": str(outside),
              "deep": "resources/../../outside.fmu"}[where]
    forged = _rewritten(ssp, tmp_path / "forged.ssp", source)
    with pytest.raises(ValueError, match=r"component \w+: its source .* is outside the SSP"):
        cosimulate(forged, 1.0, 0.01)


def test_a_component_the_ssp_does_not_hold_is_named(ssp, tmp_path, no_leftovers):
    forged = _rewritten(ssp, tmp_path / "forged.ssp", "resources/nothing.fmu")
    with pytest.raises(ValueError, match=r"the SSP holds no file 'resources/nothing.fmu'"):
        cosimulate(forged, 1.0, 0.01)


def test_an_archive_fmpy_refuses_to_extract_leaves_no_folder(ssp, tmp_path, no_leftovers):
    """fmpy's extract refuses a backslash in an entry's name after making its folder; cosimulate's is its own."""
    forged = _rewritten(ssp, tmp_path / "forged.ssp", extra={"resources\\evil.txt": b"x"})
    with pytest.raises(ValueError, match="forged.ssp cannot be extracted: Exception: Illegal path"):
        cosimulate(forged, 1.0, 0.01)


def test_a_component_that_is_no_fmu_is_named(ssp, tmp_path, no_leftovers):
    forged = _rewritten(ssp, tmp_path / "forged.ssp", "resources/not.fmu", extra={"resources/not.fmu": b"text"})
    with pytest.raises(ValueError, match=r"component \w+: resources/not.fmu is no FMU fmpy can read: BadZipFile"):
        cosimulate(forged, 1.0, 0.01)


def test_a_good_ssp_still_runs_and_leaves_nothing(ssp, no_leftovers):
    record = cosimulate(ssp, 1.0, 0.01)
    assert len(record["time"]) == 100 and record["time"][-1] == pytest.approx(1.0)
    assert all(len(v) == 100 for v in record.values())

