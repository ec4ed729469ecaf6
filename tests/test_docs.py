"""The docs site's generated pages follow the code: the command-line reference is the
parser's, the FMU reference the model descriptions', the API reference the public names."""
import importlib.util
from pathlib import Path

from fmpy import read_model_description

import attitude_fmu
from attitude_fmu.systems.cli.commands import build_parser
from attitude_fmu.systems.fmi.build import build_fmus

ROOT = Path(__file__).resolve().parent.parent
spec = importlib.util.spec_from_file_location("docs_hooks", ROOT / "docs" / "hooks.py")
hooks = importlib.util.module_from_spec(spec)
spec.loader.exec_module(hooks)


def test_the_cli_reference_is_the_parsers_and_changes_with_a_help_text():
    parser = build_parser()
    page = hooks.cli_reference(parser)
    commands = next(a for a in parser._actions if a.dest == "command").choices
    for name, sub in commands.items():
        assert f"## `attitude {name}`" in page
        for action in sub._actions:
            for flag in action.option_strings if action.dest != "help" else ():
                assert f"`{flag}" in page, (name, flag)
    latency = next(a for a in commands["estimate"]._actions if "--latency" in a.option_strings)
    latency.help = "a help text written for this test"
    assert "a help text written for this test" in hooks.cli_reference(parser)


def test_the_fmu_reference_lists_every_variable_of_every_built_fmu(tmp_path):
    build_fmus(tmp_path, ("MotionProfile",))
    page = hooks.fmu_reference(tmp_path)
    md = read_model_description(str(tmp_path / "MotionProfile.fmu"))
    assert "## MotionProfile.fmu" in page
    for v in md.modelVariables:
        assert f"| `{v.name}` | {v.causality} | {v.type} |" in page


def test_the_api_reference_documents_every_public_name():
    page = hooks.api_reference()
    assert page.count(":::") == len(attitude_fmu.__all__)
    for name in attitude_fmu.__all__:
        assert f".{name}\n" in page + "\n"


def test_the_scenarios_table_lists_every_scenario_with_its_description():
    from attitude_fmu.systems.simulation.scenarios import SCENARIOS

    page = hooks.scenarios_reference()
    assert len(page.splitlines()) == 2 + len(SCENARIOS)
    for name, s in SCENARIOS.items():
        assert f"| `{name}` | {hooks._cell(s.description)} | `{s.profile}`" in page
    guide = (ROOT / "docs" / "guide" / "recordings.md").read_text()
    assert hooks.MARKER.format("scenarios") in guide
