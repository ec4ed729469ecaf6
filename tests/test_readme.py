"""The README's Python examples run as written, in order, and show what they say."""
import re
import subprocess
import sys
from pathlib import Path

from attitude_fmu.systems.fmi.build import build_fmus

ROOT = Path(__file__).resolve().parent.parent


def test_the_python_examples_run_and_give_the_figures_their_comments_name(tmp_path):
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text[text.index("\n## Python\n"):]
    section = section[:section.index("\n## ", 1)]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 4, "the section's examples"
    imports = re.findall(r"^(?:from|import) (attitude_fmu\S*)", "".join(blocks), flags=re.M)
    assert imports and set(imports) == {"attitude_fmu"}, "the examples use the public API only"
    # in a process of their own, from a folder where dist/ holds the FMUs (an FMU loaded in
    # the test process would tie its exit to pythonfmu's, systems.fmi.cosim.fmus_loaded); the
    # installed attitude_fmu, as a user's script imports it
    build_fmus(tmp_path / "dist", ("AttitudeEstimator",))
    (tmp_path / "example.py").write_text("".join(blocks) + "\nprint(est.quat.shape, est.up.shape, est.offset.shape, "
                                         "smoothed.quat.shape)\n", encoding="utf-8")
    run = subprocess.run([sys.executable, "example.py"], cwd=tmp_path, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    table1, smoother, closed_loop_rms, fmu_vs_batch = (float(line) for line in lines[:4])
    assert round(table1, 2) == 0.33 and smoother == table1 / 2  # eq. 46; the smoother halves its error
    assert 0.1 < closed_loop_rms < 1.0
    assert fmu_vs_batch < 1e-9
    n = 6000  # a minute at 100 Hz
    assert lines[4] == f"({n}, 4) ({n}, 3) ({n}, 3) ({n}, 4)"
