"""mkdocs hooks: the reference pages generated from the code, so they cannot drift.

A page's line `<!-- generated: cli -->` becomes the reference of every `attitude` command,
from its argparse parser; `<!-- generated: api -->` the public API, from the docstrings
(mkdocstrings); `<!-- generated: fmus -->` the variables of every FMU, from the model
descriptions a build writes (built once per docs build, into a temporary folder);
`<!-- generated: scenarios -->` the table of `attitude simulate`'s scenarios
(systems/simulation/scenarios.py).
"""
from __future__ import annotations

import argparse
import atexit
import shutil
import tempfile
from functools import lru_cache
from pathlib import Path

MARKER = "<!-- generated: {} -->"


def _cell(text) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def _flags(action: argparse.Action) -> str:
    if not action.option_strings:
        return f"`{action.metavar or action.dest}`"
    value = "" if action.nargs == 0 else f" {action.metavar or action.dest.upper()}"
    return ", ".join(f"`{flag}{value}`" for flag in action.option_strings)


def _default(action: argparse.Action) -> str:
    if action.nargs == 0 or action.default in (None, argparse.SUPPRESS) or action.default == []:
        return ""
    return f"`{action.default}`"


def cli_reference(parser: argparse.ArgumentParser) -> str:
    """Markdown: for each subcommand of parser, its usage, what it does and a table of its
    arguments (flags, choices, default, help), in the parser's own words."""
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    helps = {a.dest: a.help for a in commands._choices_actions}
    out = []
    for name, sub in commands.choices.items():
        usage = sub.format_usage().removeprefix("usage: ").strip()
        out += [f"## `attitude {name}`", "", _cell(helps.get(name, "")), "", "```", usage, "```", "",
                "| argument | choices | default | meaning |", "|---|---|---|---|"]
        for action in sub._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            choices = ", ".join(f"`{c}`" for c in action.choices) if action.choices else ""
            out.append(f"| {_flags(action)} | {choices} | {_default(action)} | {_cell((action.help or '').replace('%%', '%'))} |")
        if sub.epilog:
            out += ["", "```", sub.epilog.strip(), "```"]
        out.append("")
    return "\n".join(out)


def fmu_reference(folder: Path) -> str:
    """Markdown: for each FMU under folder, its description and a table of its variables
    (name, causality, type, unit, start, description) as its model description states them."""
    from fmpy import read_model_description

    out = []
    for path in sorted(Path(folder).rglob("*.fmu")):
        md = read_model_description(str(path))
        out += [f"## {path.relative_to(folder).as_posix()}", "",
                _cell(md.description or ""), "", f"FMI {md.fmiVersion}, co-simulation; "
                f"`{md.coSimulation.modelIdentifier}`.", "",
                "| variable | causality | type | unit | start | description |", "|---|---|---|---|---|---|"]
        for v in md.modelVariables:
            out.append(f"| `{v.name}` | {v.causality} | {v.type} | {v.unit or ''} | "
                       f"{'' if v.start is None else f'`{v.start}`'} | {_cell(v.description or '')} |")
        out.append("")
    return "\n".join(out)


def api_reference() -> str:
    """mkdocstrings directives for every name of the public API (attitude_fmu.__all__), each
    from the module that defines it, in the order the package lists them."""
    import attitude_fmu

    return "\n\n".join(f"::: attitude_fmu.{attitude_fmu._API[name]}.{name}" for name in attitude_fmu.__all__)


def scenarios_reference() -> str:
    """A table of the simulator's scenarios: name, description, motion, rate and durations, seed, sensor."""
    from attitude_fmu.systems.simulation.scenarios import SCENARIOS

    out = ["| scenario | what it stands for | motion | rate | rest, motion | seed | sensor |",
           "|---|---|---|---|---|---|---|"]
    for name, s in SCENARIOS.items():
        motion = f"`{s.profile}`" + "".join(f", {k}={v:g}" for k, v in s.motion.items())
        f = s.sensor
        direction = "drawn" if f.gyro_offset_direction is None else f"along {tuple(f.gyro_offset_direction)}"
        sensor = (f"gyro {f.gyro_noise_dps:g} °/s/√Hz, offset {f.gyro_offset_dps:.3g} °/s {direction}, scale error "
                  f"{f.gyro_scale_error:g}; magnetometer {f.mag_noise:g} µT/√Hz, soft iron {f.mag_soft_iron:g} rms, "
                  f"hard iron {f.mag_hard_iron_ut:g} µT")
        out.append(f"| `{name}` | {_cell(s.description)} | {_cell(motion)} | {s.fs:g} Hz | {s.rest:g} s, "
                   f"{s.duration:g} s | {s.seed} | {_cell(sensor)} |")
    return "\n".join(out)


@lru_cache(maxsize=1)
def _built_fmus() -> Path:
    """A folder with every FMU, as python build_fmu.py writes them."""
    from attitude_fmu.systems.fmi.build import build_fmus

    folder = Path(tempfile.mkdtemp(prefix="attitude_docs_"))
    atexit.register(shutil.rmtree, folder, True)
    build_fmus(folder)
    return folder


def on_page_markdown(markdown: str, page, config, files) -> str:
    if MARKER.format("cli") in markdown:
        from attitude_fmu.systems.cli.commands import build_parser

        markdown = markdown.replace(MARKER.format("cli"), cli_reference(build_parser()))
    if MARKER.format("api") in markdown:
        markdown = markdown.replace(MARKER.format("api"), api_reference())
    if MARKER.format("scenarios") in markdown:
        markdown = markdown.replace(MARKER.format("scenarios"), scenarios_reference())
    if MARKER.format("fmus") in markdown:
        markdown = markdown.replace(MARKER.format("fmus"), fmu_reference(_built_fmus()))
    return markdown
