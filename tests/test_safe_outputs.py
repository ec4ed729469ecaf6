"""One safe writer for every file the project makes (issue 50, point 3): `attitude ssp`, `attitude export`
and build_fmu.py leave no temporary file and no build folder after SIGTERM, SIGHUP or SIGINT, and no
truncated output after a full disk (a small tmpfs where one can be mounted, else an injected write error),
the previous output keeping its bytes."""
import contextlib
import errno
import os
import shutil
import signal
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from fmpy import read_model_description

from attitude_fmu.systems.fmi.verify import write_verify_ssp
from attitude_fmu.systems.recordings import output

SIGNALS = [signal.SIGTERM, signal.SIGHUP, signal.SIGINT]
PREVIOUS = b"previous output\n"

# the command run in a child whose given function, once it has done its work, reports and waits: the moment a
# user's signal would find the temporary folder full and the output not yet replaced
STALLED = """
import functools, importlib, signal, sys, time
for name in ("SIGTERM", "SIGHUP"):  # as a user's shell leaves them, whatever the test runner's
    signal.signal(getattr(signal, name), signal.SIG_DFL)
signal.signal(signal.SIGINT, signal.default_int_handler)
target, entry, *argv = sys.argv[1:]
module_name, function = target.rsplit(":", 1)
module = importlib.import_module(module_name)
real = getattr(module, function)


def call(*args, **kwargs):
    result = real(*args, **kwargs)
    print("stalled", flush=True)
    time.sleep(120)
    return result


def write(path, *args, **kwargs):  # a replaced(): the temporary file written, the rename not yet done
    import contextlib

    @contextlib.contextmanager
    def stalled():
        with real(path, *args, **kwargs) as fh:
            yield fh
            fh.flush()
            print("stalled", flush=True)
            time.sleep(120)
    return stalled()


setattr(module, function, write if function == "replaced" else call)
main = importlib.import_module(entry).main
sys.exit(main(argv))
"""


def _stalled(tmp_path, target: str, entry: str, argv) -> tuple[subprocess.Popen, Path]:
    """The command (entry's main with argv) in a child with its own TMPDIR, stalled in target; returned
    (with that TMPDIR) once it stalls."""
    script, temporary = tmp_path / "stalled.py", tmp_path / "tmpdir"
    script.write_text(STALLED)
    temporary.mkdir()
    child = subprocess.Popen([sys.executable, str(script), target, entry, *map(str, argv)], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env={**os.environ, "TMPDIR": str(temporary)})
    line = child.stdout.readline()
    if line != "stalled\n":
        child.kill()
        pytest.fail(f"the child did not stall: {line!r} {child.communicate(timeout=60)}")
    return child, temporary


def _signalled(child, signum, program: str = "attitude") -> str:
    """The child's standard error after signum: it ended with 128 + signum, one line naming the signal."""
    child.send_signal(signum)
    _, err = child.communicate(timeout=120)
    assert child.returncode == 128 + signum, err
    assert err.splitlines()[-1].startswith(f"{program}: interrupted by {signal.Signals(signum).name}"), err
    assert "Traceback" not in err, err
    return err


@pytest.mark.parametrize("signum", SIGNALS, ids=lambda s: s.name)
def test_ssp_leaves_no_partial_file_after_a_signal(fmu_dir, tmp_path, signum):
    out = tmp_path / "out"
    out.mkdir()
    (out / "incline_wiener.ssp").write_bytes(PREVIOUS)
    child, temporary = _stalled(tmp_path, "attitude_fmu.systems.fmi.ssp:replaced", "attitude_fmu.systems.cli.commands",
                                ["ssp", "--fmu-dir", fmu_dir, "--out", out, "--profile", "incline", "--method",
                                 "wiener"])
    assert len(list(out.glob(f"*{output.PARTIAL_SUFFIX}"))) == 1  # the SSP, written whole, not yet in place
    _signalled(child, signum)
    assert sorted(p.name for p in out.iterdir()) == ["incline_wiener.ssp"]
    assert (out / "incline_wiener.ssp").read_bytes() == PREVIOUS and list(temporary.iterdir()) == []


PLANT = "import control\n\nplant = control.ss([[0.5]], [[1.0]], [[2.0]], [[0.0]], 0.1, name='plant')\n"


@pytest.mark.parametrize("signum", SIGNALS, ids=lambda s: s.name)
def test_export_leaves_no_build_folder_after_a_signal(tmp_path, signum):
    """Stopped once the binary is built: the build folders (attitude_fmu_export_*) and the stage go, the
    previous FMU stays."""
    source = tmp_path / "plant.py"
    source.write_text(PLANT)
    (tmp_path / "out.fmu").write_bytes(PREVIOUS)
    child, temporary = _stalled(tmp_path, "attitude_fmu.systems.fmi.export.native:build_binary",
                                "attitude_fmu.systems.cli.commands", ["export", f"{source}:plant", "--out",
                                                                      tmp_path / "out.fmu"])
    built = [p.name for p in temporary.iterdir()]
    assert len(built) == 1 and built[0].startswith("attitude_fmu_export_"), built
    _signalled(child, signum)
    assert list(temporary.iterdir()) == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.fmu", "plant.py", "stalled.py", "tmpdir"]
    assert (tmp_path / "out.fmu").read_bytes() == PREVIOUS


@pytest.mark.parametrize("signum", SIGNALS, ids=lambda s: s.name)
def test_build_fmu_leaves_no_build_folder_after_a_signal(tmp_path, signum):
    """Stopped once the first pythonfmu FMU is built in its temporary folder: the folder goes, the output
    folder keeps what it held."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "AttitudeEstimator.fmu").write_bytes(PREVIOUS)
    child, temporary = _stalled(tmp_path, "attitude_fmu.systems.fmi.build:guarded", "attitude_fmu.build_fmu",
                                ["--out", out])
    assert [p.name.startswith("attitude_fmu_") for p in temporary.iterdir()] == [True]
    _signalled(child, signum, "build_fmu")
    assert list(temporary.iterdir()) == [] and [p.name for p in out.iterdir()] == ["AttitudeEstimator.fmu"]
    assert (out / "AttitudeEstimator.fmu").read_bytes() == PREVIOUS


# a full disk


@pytest.fixture
def full_disk(tmp_path, monkeypatch):
    """A folder where a write runs out of space: a 64 KiB tmpfs where this process may mount one, else an
    ordinary folder in which the writer's flush to disk fails with ENOSPC (an injected write error)."""
    folder = tmp_path / "small"
    folder.mkdir()
    mounted = (os.name == "posix" and os.geteuid() == 0 and shutil.which("mount") is not None and subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(folder)], capture_output=True).returncode == 0)
    if not mounted:
        def no_space(fd):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

        monkeypatch.setattr(output.os, "fsync", no_space)
    yield folder
    if mounted:
        subprocess.run(["umount", str(folder)], check=True)


def _kept(folder: Path, name: str) -> None:
    """The previous output in folder kept its bytes, and nothing else is there."""
    assert [p.name for p in folder.iterdir()] == [name]
    assert (folder / name).read_bytes() == PREVIOUS


def test_an_ssp_on_a_full_disk_leaves_the_previous_one(fmu_dir, full_disk):
    (full_disk / "a.ssp").write_bytes(PREVIOUS)
    with pytest.raises(output.OutputError, match=r"a\.ssp: No space left on device; .* is as it was"):
        write_verify_ssp(full_disk / "a.ssp", fmu_dir, "incline", "wiener")
    _kept(full_disk, "a.ssp")


def test_an_export_on_a_full_disk_leaves_the_previous_one(tmp_path, full_disk, capsys):
    from attitude_fmu.systems.cli.commands import main

    (tmp_path / "plant.py").write_text(PLANT)
    (full_disk / "plant.fmu").write_bytes(PREVIOUS)
    assert main(["export", f"{tmp_path / 'plant.py'}:plant", "--out", str(full_disk / "plant.fmu")]) == 2
    last = capsys.readouterr().err.splitlines()[-1]  # after the build's progress lines
    assert last == (f"attitude: error: cannot write {full_disk / 'plant.fmu'}: No space left on device; "
                    f"{full_disk / 'plant.fmu'} is as it was"), last
    _kept(full_disk, "plant.fmu")


def test_build_fmus_on_a_full_disk_leaves_the_previous_ones(full_disk):
    from attitude_fmu import build_fmus

    (full_disk / "AttitudeEstimator.fmu").write_bytes(PREVIOUS)
    with pytest.raises(output.OutputError, match="No space left on device"):
        build_fmus(full_disk, names=["AttitudeEstimator"], native=(), fmi3_names=())
    _kept(full_disk, "AttitudeEstimator.fmu")


def test_the_python_backend_writes_any_output_name(tmp_path):
    """--backend python --out other_name.fmu: the FMU is guarded where it was built, then written whole (it
    once failed, "has no binaries/linux64/other_name.so to guard", after removing the old output)."""
    import control

    from attitude_fmu.systems.fmi.export.api import export_fmu

    (tmp_path / "other_name.fmu").write_bytes(PREVIOUS)
    system = control.ss([[0.5]], [[1.0]], [[2.0]], [[0.0]], 0.1, name="plant")
    path = export_fmu(system, tmp_path / "other_name.fmu", backend="python")
    with zipfile.ZipFile(path) as zf:
        names = zf.namelist()
    assert "modelDescription.xml" in names and any(n.startswith("binaries/") and "/plant." in n for n in names)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["other_name.fmu"]
    assert read_model_description(str(path)).coSimulation.canHandleVariableCommunicationStepSize  # its dt's grid


def test_copy_file_keeps_the_sources_permissions(tmp_path):
    """build_fmu's copy of what the clone's build installed: an executable stays one."""
    source = tmp_path / "tool"
    source.write_bytes(b"#!/bin/sh\n")
    source.chmod(0o751)
    with contextlib.suppress(FileNotFoundError):
        (tmp_path / "copy").unlink()
    output.copy_file(source, tmp_path / "copy")
    assert (tmp_path / "copy").read_bytes() == b"#!/bin/sh\n" and (tmp_path / "copy").stat().st_mode & 0o7777 == 0o751


def test_export_into_a_named_pipe_writes_the_fmu_through_it(tmp_path):
    """--out a named pipe: the FMU is written into it, as standard output is; the pipe stays a pipe (it was once
    replaced by a regular file)."""
    import stat
    import threading

    (tmp_path / "plant.py").write_text(PLANT)
    fifo = tmp_path / "plant.fmu"
    os.mkfifo(fifo)
    received = {}
    reader = threading.Thread(target=lambda: received.update(data=fifo.read_bytes()), daemon=True)
    reader.start()
    done = subprocess.run([sys.executable, "-m", "attitude_fmu.systems.cli.commands", "export",
                           f"{tmp_path}/plant.py:plant", "--out", str(fifo), "--backend", "python"],
                          capture_output=True, text=True, timeout=300)
    reader.join(60)
    assert done.returncode == 0, done.stderr
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)
    copy = tmp_path / "copy.fmu"
    copy.write_bytes(received["data"])
    with zipfile.ZipFile(copy) as zf:
        assert zf.testzip() is None and "modelDescription.xml" in zf.namelist()


# build_fmu.py in a clone (issue 49, point 6)

def test_build_fmu_in_a_clone_names_what_to_install_in_one_line(tmp_path):
    """A clone's build_fmu.py in a Python without nanobind (what `pip install .` leaves): exit 2, one line
    naming it, and no build folder begun."""
    from tests.native import ROOT

    script = ("import runpy, sys\n"
              "sys.modules['nanobind'] = None  # pip install . built in an isolated Python that had it\n"
              "path, sys.argv = sys.argv[1], ['build_fmu.py', *sys.argv[2:]]\n"
              "runpy.run_path(path, run_name='__main__')\n")
    before = (ROOT / "build").exists()
    done = subprocess.run([sys.executable, "-c", script, str(ROOT / "build_fmu.py"), "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr
    assert done.stderr == (f"build_fmu: error: building the clone needs nanobind in this Python ({sys.executable}): "
                           "pip install nanobind; or let the installed package build them: python -m "
                           "attitude_fmu.build_fmu\n"), done.stderr
    assert (ROOT / "build").exists() == before and not (tmp_path / "out").exists()


def test_a_failed_configuration_is_not_left_for_the_next_run(tmp_path):
    """CMake's configuration fails (here: the project says so): no cache is kept, so the next run configures
    afresh instead of failing on a build file that was never written ("ninja: error: loading 'build.ninja'")."""
    from attitude_fmu.build_fmu import cmake_build

    source, build = tmp_path / "source", tmp_path / "build"
    source.mkdir()
    (source / "CMakeLists.txt").write_text("cmake_minimum_required(VERSION 3.15)\nproject(t LANGUAGES NONE)\n"
                                           "message(FATAL_ERROR \"not today\")\n")
    with pytest.raises(subprocess.CalledProcessError):
        cmake_build(build, source=source, quiet=True)
    assert not (build / "CMakeCache.txt").exists()
    (source / "CMakeLists.txt").write_text("cmake_minimum_required(VERSION 3.15)\nproject(t LANGUAGES NONE)\n"
                                           "add_custom_target(done ALL COMMAND ${CMAKE_COMMAND} -E touch done)\n")
    cmake_build(build, source=source, quiet=True)
    assert (build / "done").is_file()
