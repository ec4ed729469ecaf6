"""The README's Python examples run as written, in order, and show what they say."""
import contextlib
import io
import re
from pathlib import Path

import numpy as np

README = Path(__file__).resolve().parent.parent / "README.md"


def test_the_python_examples_run_and_give_the_figures_their_comments_name():
    text = README.read_text(encoding="utf-8")
    section = text[text.index("\n## Python\n"):]
    section = section[:section.index("\n## ", 1)]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 3, "the section's examples"
    namespace, printed = {}, io.StringIO()
    with contextlib.redirect_stdout(printed):
        for block in blocks:
            exec(compile(block, str(README), "exec"), namespace)
    table1, smoother, closed_loop_rms = (float(line) for line in printed.getvalue().split())
    assert round(table1, 2) == 0.33 and smoother == np.float64(table1) / 2  # eq. 46; the smoother halves it
    assert 0.1 < closed_loop_rms < 1.0
    est = namespace["est"]
    n = len(namespace["gyr"])
    assert est.quat.shape == (n, 4) and est.up.shape == (n, 3) and est.offset.shape == (n, 3)
    assert namespace["smoothed"].quat.shape == (n, 4)
