"""Names that cannot become code (issue 50, point 1): every text of an exported FMU's generated files goes
through systems.fmi.interface.escaping, one point per language. The truth: the C the exporter writes has the
tokens of a plain name's export but inside string literals, which decode back to the names; fmpy parses and
validates every model description (its XML schema and its own grammar of structured names); Python's parser
reads the generated script's docstring back as the text; and the exploits of the issue, built and loaded,
leave no trace."""
import ast
import re
from functools import cache
import subprocess
import sys
import zipfile

import control
import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu
from hypothesis import HealthCheck, event, given, seed, settings
from hypothesis import strategies as st

from attitude_fmu.systems.fmi.export.api import export_fmu
from attitude_fmu.systems.fmi.export.flatten import flatten
from attitude_fmu.systems.fmi.export.native import stage_files
from attitude_fmu.systems.fmi.export.python import script_text
from attitude_fmu.systems.fmi.interface.escaping import STRUCTURED, fmi_name
from attitude_fmu.systems.fmi.interface.model_description import start_text
from attitude_fmu.systems.fmi.interface.variables import REAL, Variable
from tests import native

BUILD = ("AF_WERROR=ON", *(("AF_SANITIZE=ON",) if native.sanitized_build() is not None else ()))
DT = 0.1
C_TOKENS = re.compile(r'(?P<comment>/\*.*?\*/|//[^\n]*)|(?P<string>"(?:[^"\\\n]|\\.)*")|(?P<other>[^"/]+|/)', re.S)
C_NUMBER = re.compile(r"(?<![\w.])-?(?:\d+\.?\d*(?:[eE][+-]?\d+)?|NAN|HUGE_VAL)(?![\w.])")
# what the issue's probe put into a diagram's name: the end of a comment, an include and a constructor
INJECTED = ('x */\n#include <stdio.h>\n__attribute__((constructor)) static void pwn(void) '
            '{ FILE *f = fopen("{marker}", "w"); if (f) fclose(f); }\n/* ??= "q" \\')


def plant(name: str, label_in: str, label_out: str, entries) -> control.StateSpace:
    """A discrete state space of the entries A, B, C, D (one state), the input label_in and the output
    label_out, named name (set as an attribute: python-control refuses a '.' in names it is given)."""
    a, b, c, d = entries
    system = control.ss([[a]], [[b]], [[c]], [[d]], DT, inputs=[label_in], outputs=[label_out])
    system.name = name
    return system


@cache
def plain_files(fmi: str) -> dict:
    """The staged files of a diagram of plain names."""
    return stage_files("Probe", fmi, flatten(plant("plain", "i", "o", (0.5,) * 4)), None, DT,
                       "python-control system plain")


def c_structure(text: str) -> tuple[str, list[str]]:
    """(the C text with comments dropped, string literals as "" and numbers as 0; its string literals)."""
    shape, strings = [], []
    for match in C_TOKENS.finditer(text):
        if match.group("string"):
            shape.append('""')
            strings.append(match.group("string"))
        elif match.group("other"):
            shape.append(C_NUMBER.sub("0", match.group("other")))
    return "".join(shape), strings


def c_decoded(literal: str) -> str:
    """A C string literal of c_string's (octal escapes and \\\\, \\", \\?) as the text it holds."""
    raw = re.sub(r"\\([0-7]{3}|.)", lambda m: chr(int(m.group(1), 8)) if len(m.group(1)) == 3 else m.group(1),
                 literal[1:-1])
    return raw.encode("latin-1").decode("utf-8")


def model_description(files: dict, tmp_path):
    path = tmp_path / "modelDescription.xml"
    path.write_bytes(files["modelDescription.xml"])
    return read_model_description(str(path), validate=True, validate_variable_names=True)


PLAIN = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,8}", fullmatch=True)
QUOTED = st.from_regex(r"'[A-Za-z0-9_!#$%&()*+,\-./:;<>=?@\[\]^{}|~ ]{1,8}'", fullmatch=True)
TEXT = st.text(max_size=24) | st.sampled_from(["a*/b", "%s%n", "a<b", "\ud800", "x\x01", "time", INJECTED])


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # python-control's arithmetic on the infinite entries
@pytest.mark.parametrize("fmi", ["2.0", "3.0"])
@seed(50)
@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                   HealthCheck.too_slow])
@given(name=st.text(st.characters(blacklist_categories=("Cs", "Cc")), max_size=24) | TEXT,
       label_in=PLAIN | QUOTED | TEXT, label_out=PLAIN | QUOTED | TEXT,
       entries=st.tuples(*[st.floats(allow_nan=True, allow_infinity=True) | st.just(0.5)] * 4))
def test_any_name_is_escaped_or_refused_before_a_file_is_written(tmp_path, fmi, name, label_in, label_out, entries):
    """Whatever the system's name (its block's in the C tables), its labels and its matrices' entries: the
    export is refused with a ValueError (a label outside structured naming, two of one name, a text XML cannot
    hold), or its C has the tokens of a plain export's and names only inside string literals that decode to
    them, and its model description is valid for fmpy with the labels as the variables' names."""
    try:
        system = plant(name, label_in, label_out, entries)
    except ValueError:  # python-control's own refusal: two signals of one name
        return
    try:
        files = stage_files("Probe", fmi, flatten(system), None, DT, f"python-control system {name}")
    except ValueError as refusal:
        assert not (STRUCTURED.fullmatch(label_in) and STRUCTURED.fullmatch(label_out)
                    and label_in != label_out) or re.search(r"U\+|named twice", str(refusal)), refusal
        event("refused")
        return
    event("exported")
    plain = plain_files(fmi)
    for header in ("sources/diagram_tables.h", "sources/Probe_variables.h"):
        shape, strings = c_structure(files[header].decode("ascii"))
        assert shape == c_structure(plain[header].decode("ascii"))[0]
        texts = [c_decoded(s) for s in strings]
        assert name in texts if header.endswith("tables.h") else label_in in texts and label_out in texts
    md = model_description(files, tmp_path)
    assert [v.name for v in md.modelVariables][:2] == [label_in, label_out]
    assert md.description == f"python-control system {name}"


def test_structured_names_fmpy_takes_and_those_refused():
    """fmi_name takes names FMI's grammar holds (as fmpy parses it) and refuses what would break it."""
    for name in ("gyr_x", "block.A[0,1]", "sys[3].D[0,0]", "'a<b'", "'%s'", r"'it\'s'", "u[0]"):
        assert fmi_name(name) == name
    for name in ("a<b", "%s", "", "1x", "a..b", "a[]", "'a\nb'", "'", "a b", "é", "'a\\'", "x\x01"):
        with pytest.raises(ValueError, match="no FMI variable name"):
            fmi_name(name)


def test_an_infinite_entry_is_an_xs_double():
    assert start_text(Variable("A", REAL, "parameter", "fixed", (np.inf, -np.inf, np.nan, 0.1), "", 0,
                               dimensions=(4,))) == "INF -INF NaN 0.1"


@pytest.mark.parametrize("fmi", ["2.0", "3.0"])
def test_the_issues_constructor_in_a_name_stays_a_string(tmp_path, fmi):
    """The issue's probe: a diagram named with the end of a comment, #include <stdio.h> and a constructor
    that writes a file; built (warnings as errors) and run by fmpy, the FMU writes no file, computes what
    python-control does and carries the name as its blocks' name, in its C as a string."""
    marker = tmp_path / "constructor_ran"
    name = INJECTED.replace("{marker}", str(marker))
    system = plant(name, "'u<0>'", "y", (0.5, 1.0, 2.0, 0.25))
    path = export_fmu(system, tmp_path / "Injected.fmu", name="Injected", fmi_version=fmi, cmake_options=BUILD)
    u = np.sin(np.arange(20) * 0.3)
    signals = np.zeros(20, dtype=[("time", float), ("'u<0>'", float)])
    signals["time"], signals["'u<0>'"] = np.arange(20) * DT, u
    result = simulate_fmu(str(path), stop_time=20 * DT, step_size=DT, output_interval=DT, input=signals,
                          output=["y"])
    assert not marker.exists()
    expected = control.input_output_response(system, np.arange(20) * DT, u).outputs
    np.testing.assert_allclose(result["y"][1:21], expected, rtol=0, atol=1e-9)
    assert validate_fmu(str(path)) == []
    with zipfile.ZipFile(path) as zf:
        tables = zf.read("sources/diagram_tables.h").decode("ascii")
    shape, strings = c_structure(tables)
    assert "stdio" not in shape and "constructor" not in shape and name in map(c_decoded, strings)


def test_the_python_backends_script_holds_any_title_as_its_docstring(tmp_path):
    """script_text's docstring is a literal Python reads back as the text, whatever the system's name; the
    export of a name that closes the docstring and runs code writes no file, at export nor when loaded."""
    for title in ('"""\nimport os\n"""', "'''", "\\", "\ud800", "\x00\n\r", INJECTED):
        tree = ast.parse(script_text("Model", title))
        assert [type(node).__name__ for node in tree.body] == ["ImportFrom", "ClassDef"]
        assert ast.get_docstring(tree.body[1], clean=False) == f"python-control system {title}, exported by attitude_fmu."
    for bad in ("class", "None", "a-b", "é"):
        with pytest.raises(ValueError, match="Python identifier"):
            script_text(bad, "x")
    marker = tmp_path / "docstring_ran"
    name = f'"""\nimport pathlib; pathlib.Path({str(marker)!r}).write_text("x")\n"""'
    system = control.nlsys(lambda t, x, u, p: 0.5 * x + u, lambda t, x, u, p: x, inputs=["u"], outputs=["y"],
                           states=1, dt=DT, name=name)
    path = export_fmu(system, tmp_path / "Docstring.fmu", name="Docstring", backend="python")
    with zipfile.ZipFile(path) as zf:
        script = zf.read("resources/Docstring.py").decode("utf-8")
    assert ast.get_docstring(ast.parse(script).body[1]) == f"python-control system {name}, exported by attitude_fmu."
    load = ("import sys\nfrom fmpy import simulate_fmu\n"
            "simulate_fmu(sys.argv[1], stop_time=0.5, step_size=0.1, output_interval=0.1, output=['y'])\nimport os\nos._exit(0)\n")
    run = subprocess.run([sys.executable, "-c", load, str(path)], capture_output=True, text=True, cwd=tmp_path)
    assert run.returncode == 0, run.stderr[-3000:]
    assert not marker.exists()


@pytest.mark.parametrize("label, fmi, match", [
    ("a<b", "2.0", "no FMI variable name"), ("%s", "3.0", "no FMI variable name"),
    ("x\x01", "2.0", "no FMI variable name"), ("time", "3.0", "time named twice")])
def test_labels_that_would_break_the_model_description_are_refused(tmp_path, label, fmi, match):
    with pytest.raises(ValueError, match=match):
        export_fmu(plant("plant", label, "y", (0.5,) * 4), tmp_path / "plant.fmu", fmi_version=fmi)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name, backend, match", [
    ("x\x01y", "native", "U\\+0001"), ("p" * 300, "native", "300 characters"),
    ("int", "native", "C identifier"), ("lambda", "python", "C identifier|Python identifier")])
def test_names_that_cannot_name_the_files_are_refused_in_one_line(tmp_path, name, backend, match):
    system = control.ss([[0.5]], [[1.0]], [[2.0]], [[0.0]], DT, inputs=["u"], outputs=["y"], name="plant")
    with pytest.raises(ValueError, match=match) as refused:
        if "\x01" in name:
            export_fmu(plant(name, "u", "y", (0.5,) * 4), tmp_path / "plant.fmu", name="plant")
        else:
            export_fmu(system, tmp_path / "plant.fmu", name=name, backend=backend)
    assert "\n" not in str(refused.value)
    assert list(tmp_path.iterdir()) == []


def test_c_decoded_reads_what_c_string_writes():
    from attitude_fmu.systems.fmi.interface.escaping import c_string

    for text in ("plain", 'q"\\?', "é\n\x00", INJECTED):
        assert c_decoded(c_string(text)) == text
