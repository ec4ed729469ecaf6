"""The generator of the C parameter headers (blocks/core/generate_tables.py): a field added
to blocks.params.Param reaches AfStageParam with every stage's value, without a change to the
generator; a field C cannot hold is refused; sim_profiles.h, as generated and as the native
MotionProfile FMUs carry it in sources/, holds systems/simulation/profile_table.py's values.
(That the C core refuses each parameter as its table entry says: tests/test_refusals.py,
tests/test_motion_steps.py.)"""
import codecs
import dataclasses
import importlib.util
import math
import re
import sys
import zipfile
from pathlib import Path

import pytest

from attitude_fmu.blocks.params import Param
from attitude_fmu.systems.fmi.native import built
from attitude_fmu.systems.simulation.profile_table import GRAVITY, PROFILES

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


C_TOKEN = re.compile(r'"(?:[^"\\]|\\.)*"|[^\s,{}]+')  # a C string literal, or a number or name
C_NAMES = {"NULL": None, "NAN": math.nan, "HUGE_VAL": math.inf, "-HUGE_VAL": -math.inf}


def _c_value(token: str):
    """A C literal of the header read back: a string unescaped (UTF-8), a number, NULL as None."""
    if token.startswith('"'):
        return codecs.escape_decode(token[1:-1].encode("ascii"))[0].decode("utf-8")
    if token in C_NAMES:
        return C_NAMES[token]
    return float(token) if re.fullmatch(r"-?[\d.]+(e[-+]?\d+)?", token) else token


def _c_array(header: str, name: str) -> list[list]:
    """The rows of the static array name in header, each as its values."""
    body = re.search(rf"{name}\[\w+\] = {{\n(.*?)\n}};", header, re.S).group(1)
    return [[_c_value(t) for t in C_TOKEN.findall(line)] for line in body.splitlines()]


def _row(p: Param) -> list:
    """p as a row of SimProfileParam reads back: every field of Param in its order, a tuple field as
    its array and count (None, 0 where None)."""
    row = []
    for field in dataclasses.fields(p):
        value = getattr(p, field.name)
        row += [None, 0] if value is None and "tuple[" in str(field.type) else [value]
    return row


def _profiles_headers(generator):
    yield "generated", generator.profiles_text()
    for fmu in ("native/MotionProfile.fmu", "native/fmi3/MotionProfile.fmu"):
        with zipfile.ZipFile(built(fmu)) as archive:
            yield fmu, archive.read("sources/sim_profiles.h").decode("ascii")


def test_the_profiles_header_carries_the_profile_table(generator):
    """Every profile of profile_table.PROFILES, in its order, with its summary and each parameter's
    name, default, unit, meaning, allow_zero, low and high, and gravity's: in the generated text and
    in the FMUs' sources (the header they are built with), read back from the C literals."""
    for source, header in _profiles_headers(generator):
        assert f"#define SIM_N_PROFILES {len(PROFILES)}\n" in header, source
        assert f"#define SIM_PROFILE_MAX_PARAMS {max(len(ps) for _, ps in PROFILES.values())}\n" in header, source
        assert _c_array(header, "SIM_PROFILES") == [
            [name, summary, len(params), f"SIM_PROFILE_PARAMS_{name}"] for name, (summary, params) in PROFILES.items()
        ], source
        for name, (_, params) in PROFILES.items():
            assert _c_array(header, f"SIM_PROFILE_PARAMS_{name}") == [_row(p) for p in params], (source, name)
        assert _c_array(header, "SIM_PROFILE_GRAVITY") == [_row(GRAVITY)], source
