"""The documentation/ folder of an FMU (FMI 2.0 and 3.0 alike): index.html, which lists the
variables of the FMU's table (systems.fmi.interface.variables) with their units, causalities and start
values and says when the inputs are taken and the outputs hold, and licenses/LICENSE, the
project's license. Only the standard library is imported: the build runs it."""
from __future__ import annotations

from html import escape
from pathlib import Path

from attitude_fmu.systems.fmi.interface.model_description import COPYRIGHT, start_text
from attitude_fmu.systems.fmi.interface.variables import DISPLAY_UNITS, ENUMERATION, IN, OUT

LICENSE_FILE = Path(__file__).resolve().parents[3] / "LICENSE"  # the project's

# the time convention of every step: sample k of a stream is the one whose interval (t[k], t[k+1]] the
# step doStep(t[k], t[k+1] - t[k]) covers
STEP = ("A master sets the inputs of sample k, then calls doStep(t[k], h) with h = t[k+1] - t[k]: the inputs "
        "are held over the step that ends at t[k+1]. ")
CONVENTIONS = {
    "AttitudeEstimator": STEP + "The inputs of sample k are the gyro's mean rate over (t[k], t[k+1]] "
    "(gyr_samples mean; point: the rate at t[k+1]) and the specific force and magnetic field at t[k+1] "
    "(acc_samples point). After the step the outputs are the estimate at sample k, that is at t[k+1]; "
    "no output depends on an input within the step. Steps run on the grid of Ts from the start time: a step "
    "runs the samples it reaches with its inputs held; one that reaches none holds the outputs.",
    "NoOpEstimator": STEP + "doStep does nothing: the outputs keep their start values (a benchmark's baseline).",
    "ImuSensor": STEP + "The inputs of sample k are the true angular rate's mean over (t[k], t[k+1]] and the "
    "specific force and magnetic field at t[k+1]; after the step the outputs are the measurements of sample k. "
    "Before the first step (in Initialization Mode and after it) the outputs are the sensor's model of its "
    "inputs without noise.",
    "MotionProfile": "doStep(t[k], h) with h = t[k+1] - t[k] sets the outputs of sample k: the mean angular "
    "rate over (t[k], t[k+1]] and the specific force, magnetic field and true orientation at t[k+1]. Before "
    "the first step (in Initialization Mode and after it) they are the motion's at the start time: that "
    "instant's rate and specific force. The FMU has no inputs.",
}
EXPORTED = STEP + ("After the step the outputs are the exported python-control system's outputs at sample k, as "
                   "control.input_output_response computes them (attitude_fmu.export_fmu).")


def _start(v) -> str:
    if v.initial == "calculated":
        return "calculated (at the start time)"
    if v.type == ENUMERATION:
        return f"{v.items[v.start - 1]} ({v.start})"
    return start_text(v)


def _unit(v) -> str:
    if v.unit is None:
        return ""
    return f"{v.unit} (shown in {DISPLAY_UNITS[v.unit][0]})" if v.unit in DISPLAY_UNITS else v.unit


def index_html(name: str, description: str, fmi: str, version: str, variables, convention: str | None = None) -> str:
    """documentation/index.html of the FMU name (FMI version fmi, the project's version): its
    description, the time convention (default CONVENTIONS[name]), and a table of its variables by causality."""
    rows = []
    for causality, title in ((IN, "Inputs"), (OUT, "Outputs"), ("parameter", "Parameters")):
        chosen = [v for v in variables if v.causality == causality]
        if not chosen:
            continue
        rows.append(f'<tr><th colspan="6">{title}</th></tr>')
        for v in chosen:
            items = (f"<br>items: {escape(', '.join(f'{k} = {n}' for k, n in enumerate(v.items, 1)))}"
                     if v.type == ENUMERATION else "")
            rows.append(f"<tr><td><code>{escape(v.name)}</code></td><td>{v.value_reference}</td>"
                        f"<td>{escape(v.type)}</td><td>{escape(_unit(v))}</td><td>{escape(_start(v))}</td>"
                        f"<td>{escape(v.description)}{items}</td></tr>")
    return "\n".join([
        "<!DOCTYPE html>",
        '<html lang="en">',
        f'<head><meta charset="utf-8"><title>{escape(name)}</title></head>',
        "<body>",
        f"<h1>{escape(name)}</h1>",
        f"<p>{escape(description)}</p>",
        f"<p>FMI {escape(fmi)} co-simulation; attitude-fmu {escape(version)}. Units are SI; angles are "
        "computed in rad and shown in deg. Quaternions are [w, x, y, z], sensor to earth (ENU, z up).</p>",
        "<h2>Time convention</h2>",
        f"<p>{escape(convention or CONVENTIONS[name])}</p>",
        "<h2>Variables</h2>",
        '<table border="1" cellpadding="3">',
        "<tr><th>name</th><th>value reference</th><th>type</th><th>unit</th><th>start</th><th>description</th></tr>",
        *rows,
        "</table>",
        "<h2>License</h2>",
        f'<p>{escape(COPYRIGHT)}. MIT License: see <a href="licenses/LICENSE">licenses/LICENSE</a>.</p>',
        "</body>",
        "</html>",
        "",
    ])


def documentation_files(name: str, description: str, fmi: str, version: str, variables,
                        convention: str | None = None) -> dict[str, bytes]:
    """The FMU's documentation/ files by their path in it (convention: index_html's)."""
    return {"documentation/index.html": index_html(name, description, fmi, version, variables,
                                                   convention).encode("utf-8"),
            "documentation/licenses/LICENSE": LICENSE_FILE.read_bytes()}


def write_documentation(folder, name: str, description: str, version: str) -> Path:
    """The documentation/ files of the pythonfmu FMU name (fmu_src/<name>.py: AttitudeEstimator,
    ImuSensor, MotionProfile) with its description written into folder, for pythonfmu's
    FmuBuilder.build_FMU(documentation_folder=folder); returns folder."""
    from attitude_fmu.systems.fmi.interface.generate import MODELS  # the interfaces, which the native FMUs share

    folder = Path(folder)
    for path, data in documentation_files(name, description, "2.0", version, MODELS[name].interface()).items():
        target = folder / Path(path).relative_to("documentation")
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)
    return folder
