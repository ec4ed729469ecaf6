"""The README and the docs' Python guide as a newcomer uses them: their examples run as
written and show what they say, their commands exist (the cheap ones run), and the README's
results are those of the files docs/figures.py writes."""
import json
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from attitude_fmu.systems.cli.commands import build_parser

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")
GENERATED = ROOT / "docs" / "generated"


@pytest.fixture(scope="module")
def fmu_folder(fmu_dir, tmp_path_factory):
    """A folder whose dist/ holds the FMUs (the session's, attitude_fmu.build_fmus), where the
    examples run (each in a process of its own: an FMU loaded in the test process would tie
    its exit to pythonfmu's, systems.fmi.cosim.fmus_loaded)."""
    folder = tmp_path_factory.mktemp("examples")
    shutil.copytree(fmu_dir, folder / "dist")
    for args in _readme_commands():
        if args[0] == "ssp":  # as written, where the README's examples run
            run = subprocess.run([sys.executable, "-m", "attitude_fmu.systems.cli.commands", *args], cwd=folder,
                                 capture_output=True, text=True)
            assert run.returncode == 0, run.stderr[-2000:]
    return folder


def _readme_commands():
    """The attitude commands of the README's indented command lines, as argument lists."""
    commands = []
    for line in README.splitlines():
        if line.startswith("    ") and "attitude " in line:
            for part in line.strip().split("&&"):
                words = shlex.split(part)
                if words and words[0].endswith("attitude"):
                    commands.append(words[1:])
    return commands


def _python_blocks(text: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def _run(folder: Path, code: str) -> list[str]:
    (folder / "example.py").write_text(code, encoding="utf-8")
    run = subprocess.run([sys.executable, "example.py"], cwd=folder, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-3000:]
    return run.stdout.splitlines()


def test_the_readme_is_short():
    assert len(README.splitlines()) <= 150


def test_the_readmes_python_examples_run_and_show_what_their_comments_say(fmu_folder):
    blocks = _python_blocks(README)
    assert len(blocks) == 3, "Python, an FMU in fmpy, an SSP in libcosim"
    imports = re.findall(r"^(?:from|import) (attitude_fmu\S*)", "".join(blocks), flags=re.M)
    assert imports and set(imports) == {"attitude_fmu"}, "the examples use the public API only"
    *figures, ran = _run(fmu_folder, "".join(blocks))
    table1, block_vs_batch, fmu_vs_batch = map(float, figures)
    assert round(table1, 2) == 0.33  # eq. 50, Table 1's first cell
    assert block_vs_batch == 0.0 and fmu_vs_batch < 1e-9
    assert ran == "True"  # libcosim ran the SSP attitude ssp wrote


def test_the_docs_python_guide_runs_and_shows_what_it_says(fmu_folder):
    blocks = _python_blocks((ROOT / "docs" / "guide" / "python.md").read_text(encoding="utf-8"))
    assert len(blocks) == 4, "the guide's examples"
    lines = _run(fmu_folder, "".join(blocks) + "\nprint(est.quat.shape, est.up.shape, est.offset.shape, "
                 "smoothed.quat.shape)\n")
    table1, smoother, closed_loop_rms, fmu_vs_batch = (float(line) for line in lines[:4])
    assert round(table1, 2) == 0.33 and smoother == table1 / 2  # eq. 46; the smoother halves its error
    assert 0.1 < closed_loop_rms < 1.0
    assert fmu_vs_batch < 1e-9
    n = 6000  # a minute at 100 Hz
    assert lines[4] == f"({n}, 4) ({n}, 3) ({n}, 3) ({n}, 4)"


def test_the_readmes_commands_exist_and_the_cheap_ones_run(tmp_path):
    """Every attitude command line parses (its verb and flags exist); estimate and plot run
    on a recording of the README's format."""
    commands = _readme_commands()
    assert {c[0] for c in commands} == {"verify", "estimate", "plot", "ssp"}
    parser = build_parser()
    for args in commands:
        parser.parse_args(args)  # an unknown verb or flag exits
    fs, n = 100.0, 600
    t = np.arange(n) / fs
    rng = np.random.default_rng(1)
    data = np.column_stack([t, rng.normal(0, 0.1, (n, 3)), rng.normal(0, 0.1, (n, 3)) + [0, 0, 9.81],
                            np.tile([20.0, 5.0, -40.0], (n, 1))])
    np.savetxt(tmp_path / "walk.csv", data, delimiter=",", comments="",
               header="t,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z,mag_x,mag_y,mag_z")
    for args in commands:
        if args[0] in ("estimate", "plot"):
            run = subprocess.run([sys.executable, "-m", "attitude_fmu.systems.cli.commands", *args], cwd=tmp_path,
                                 capture_output=True, text=True)
            assert run.returncode == 0, run.stderr[-2000:]
    assert (tmp_path / "walk_attitude.csv").is_file() and (tmp_path / "walk.png").is_file()


def test_the_readmes_results_are_those_the_figure_script_wrote():
    section = README[README.index("\n## Results\n"):]
    section = section[:section.index("\n## ", 1)]
    table1 = json.loads((GENERATED / "table1.json").read_text())
    worst = max(abs(c["simulated_deg"] / c["analytic_deg"] - 1) for r in table1 for c in r["cells"])
    assert f"within {100 * worst:.1f} % of eq. 50" in section
    online = json.loads((GENERATED / "broad.json").read_text())["mean"]
    offline = json.loads((GENERATED / "broad_offline.json").read_text())["mean"]
    incl, head = "inclination_rmse_deg", "heading_rmse_deg"
    assert (f"inclination {online['wiener'][incl]:.2f}° against vqf's\n  {online['vqf'][incl]:.2f}° online, "
            f"{offline['wiener_offline'][incl]:.2f}° against vqf_offline's {offline['vqf_offline'][incl]:.2f}° "
            f"offline; heading {online['wiener'][head]:.2f}° against vqf 9D's\n  "
            f"{online['vqf_9d'][head]:.2f}°") in section
    bench = json.loads((GENERATED / "bench.json").read_text())
    assert f"about {bench['ratio_vs_vqf']['wiener_held']:.0f}× the samples per second" in section
    assert (f"tracks the gyro offset, {bench['ratio_vs_vqf']['wiener_offset']:.1f}× (9D: "
            f"{bench['ratio_vs_vqf_9d']['wiener_9d']:.1f}× vqf 9D's)") in section
    io = json.loads((GENERATED / "bench_io.json").read_text())["ratio_vs_peers"]
    assert (f"in {io['csv_to_csv']:.2f}× the time of pandas + vqf + pandas (Parquet: "
            f"{io['parquet_to_parquet']:.2f}×)") in section
    fmu = json.loads((GENERATED / "bench_fmu.json").read_text())
    assert f"native FMU's step {fmu['native_speedup_c_host']:.0f}× faster than the pythonfmu one's" in section
