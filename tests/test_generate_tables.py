"""The generator of the C core's parameter header (blocks/core/generate_tables.py): a field added
to blocks.params.Param reaches AfStageParam with every stage's value, without a change to the
generator; a field C cannot hold is refused. (That the C core refuses each parameter as its
table entry says: tests/test_refusals.py.)"""
import dataclasses
import importlib.util
import sys
from pathlib import Path

import pytest

from attitude_fmu.blocks.params import Param

GENERATOR = Path(__file__).resolve().parents[1] / "blocks" / "core" / "generate_tables.py"


@pytest.fixture(scope="module")
def generator():
    spec = importlib.util.spec_from_file_location("attitude_fmu.blocks.core.generate_tables", GENERATOR)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # (its dataclasses look their module up there)
    spec.loader.exec_module(module)
    return module


def test_a_field_param_grows_is_carried_into_the_header(generator, monkeypatch):
    """Fields added to blocks.params.Param (here an optional string and an optional tuple)
    appear in AfStageParam with every stage's value: a tuple as a static array and its
    count, None as NULL."""
    @dataclasses.dataclass(frozen=True)
    class GrownParam(Param):
        source: str | None = None
        marks: tuple[float, ...] | None = None

    grown = [(name, owner, label, tuple(GrownParam(**dataclasses.asdict(p), source="datasheet" if i else None,
                                                   marks=(0.5, float(i)) if i == 1 else None)
                                        for i, p in enumerate(ps))) for name, owner, label, ps in generator.stages()]
    monkeypatch.setattr(generator, "Param", GrownParam)
    monkeypatch.setattr(generator, "stages", lambda: grown)
    header = generator.header_text()
    assert "static const double AF_STAGE_PARAMS_luinge_tilt_sd_marks[2] = {0.5, 1.0};" in header
    assert '{AF_P_tilt_sd, "tilt_sd", 0.05, "rad", ' in header
    assert '"datasheet", AF_STAGE_PARAMS_luinge_tilt_sd_marks, 2},' in header  # luinge's second parameter
    assert ", NULL, NULL, 0}," in header  # and a first one: no source, no marks


def test_a_param_field_c_cannot_hold_is_refused(generator, monkeypatch):
    @dataclasses.dataclass(frozen=True)
    class WrongParam(Param):
        flags: dict | None = None

    monkeypatch.setattr(generator, "Param", WrongParam)
    with pytest.raises(ValueError, match=r"Param.flags: no C type for 'dict \| None'"):
        generator.header_text()
