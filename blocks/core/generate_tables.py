"""The C headers of the parameter tables, written by the build from the Python tables so that
they cannot drift, each parameter field by field as blocks.params.Param holds it (default NaN
where Python's is None, the plausible range low and high, choices as a static array or NULL;
CField):

- af_params.h, the estimator's (blocks/tuning.py): every tuning parameter's name and index (in
  the order of blocks.tuning.uses, the estimator FMU's variables'), each stage's parameters;
- sim_profiles.h, the simulation's (systems/simulation/profile_table.py): every motion profile's
  name, summary and parameters, and gravity's.

    python blocks/core/generate_tables.py DIR    # writes DIR/af_params.h, DIR/sim_profiles.h (CMake runs it)

Only the standard library is needed: the package's folder is loaded as attitude_fmu without
its dependencies. The headers are generated into the build folder, never committed; the C core
(blocks/core) includes "af_params.h", the simulation's (systems/simulation/core) "sim_profiles.h".
"""
from __future__ import annotations

import dataclasses
import importlib.util
import math
import re
import sys
from pathlib import Path

if __package__ in (None, ""):  # run as a script by the build: this clone's folder as attitude_fmu
    _root = Path(__file__).resolve().parents[2]
    _spec = importlib.util.spec_from_file_location("attitude_fmu", _root / "__init__.py",
                                                   submodule_search_locations=[str(_root)])
    sys.modules["attitude_fmu"] = importlib.util.module_from_spec(_spec)
    _spec.loader.exec_module(sys.modules["attitude_fmu"])

from attitude_fmu.blocks.params import Param  # noqa: E402
from attitude_fmu.blocks.tuning import (DRIFT_BLOCK_TAUS, DRIFT_SIGMAS, ESTIMATORS, GUARD_NOISE_MARGIN,  # noqa: E402
                                         METHODS, uses)
from attitude_fmu.systems.simulation.profile_table import GRAVITY, PROFILES  # noqa: E402

HEADER = "af_params.h"
PROFILES_HEADER = "sim_profiles.h"
ESTIMATOR_STAGES = ("gyro_offset", "heading")  # the C names of blocks.pipeline.causal.ESTIMATORS, in its order
C_TYPES = {"str": "const char *", "float": "double", "bool": "int", "int": "int"}  # of a Param field's values
NONE_IN_C = {"float": "NAN", "str": "NULL"}  # None as an optional field's C value (where its type has one)
TUPLE = re.compile(r"tuple\[(\w+), \.\.\.\]")  # a field of several values: tuple[float, ...]
C_KEYWORDS = {  # C99's
    "auto", "break", "case", "char", "const", "continue", "default", "do", "double", "else", "enum", "extern", "float",
    "for", "goto", "if", "inline", "int", "long", "register", "restrict", "return", "short", "signed", "sizeof",
    "static", "struct", "switch", "typedef", "union", "unsigned", "void", "volatile", "while"}


def stages() -> list[tuple[str, str, str, tuple[Param, ...]]]:
    """(C name, owner as resolve_params (params.c) names it, label as
    blocks.pipeline.causal.split_params names it, params) of every method, then of the
    gyro-offset and heading estimators."""
    if len(ESTIMATORS) != len(ESTIMATOR_STAGES):
        raise ValueError(f"blocks.pipeline.causal.ESTIMATORS has {len(ESTIMATORS)} stages; "
                         f"generate_tables.ESTIMATOR_STAGES names {len(ESTIMATOR_STAGES)}")
    methods = [(name, f"method {name!r}", f"the method {name}", params) for name, (_, params) in METHODS.items()]
    return methods + [(name, label, label, params) for name, (label, params) in zip(ESTIMATOR_STAGES, ESTIMATORS.items())]


def c_string(text: str) -> str:
    """text as a C string literal: UTF-8, bytes outside printable ASCII as octal escapes; ValueError
    for a lone surrogate, which UTF-8 cannot hold."""
    out = []
    try:
        data = text.encode("utf-8")
    except UnicodeEncodeError as exc:
        raise ValueError(f"{text[:80]!r} holds the lone surrogate U+{ord(text[exc.start]):04X}, which UTF-8 cannot "
                         f"hold") from None
    for byte in data:
        char = chr(byte)
        if char in '\\"?':
            out.append("\\" + char)
        elif 32 <= byte < 127:
            out.append(char)
        else:
            out.append(f"\\{byte:03o}")
    return '"' + "".join(out) + '"'


def c_double(value: float | None) -> str:
    """value as a C double that reads back exactly (NAN for None or NaN)."""
    if value is None or math.isnan(value):
        return "NAN"
    if math.isinf(value):
        return "HUGE_VAL" if value > 0 else "-HUGE_VAL"
    return repr(float(value))


def c_value(value, type_name: str) -> str:
    """value as a C literal of the Param field type type_name (a key of C_TYPES)."""
    if type_name == "str":
        return c_string(value)
    if type_name in ("bool", "int"):
        return str(int(value))
    return c_double(value)


@dataclasses.dataclass(frozen=True)
class CField:
    """A field of blocks.params.Param as AfStageParam holds it: one value of the C type of
    element (C_TYPES), or, where sequence (tuple[element, ...]), a pointer to a static array
    of them (NULL for None) and their count n_<name>; None where optional (X | None)."""

    name: str  # Python's
    c_name: str  # name, or name_value where name is a C keyword
    element: str  # a key of C_TYPES
    sequence: bool
    optional: bool

    def members(self) -> list[str]:
        """Its declarations in AfStageParam."""
        c_type = C_TYPES[self.element]
        if not self.sequence:
            return [f"{c_type}{'' if c_type.endswith('*') else ' '}{self.c_name};"]
        pointer = f"{c_type}const *" if c_type.endswith("*") else f"const {c_type} *"
        return [f"{pointer}{self.c_name};{' /* NULL: None */' if self.optional else ''}", f"int n_{self.name};"]

    def array(self, value, array_name: str) -> str | None:
        """The static array that holds a sequence's value (None where no array is needed)."""
        if not self.sequence or value is None:
            return None
        if not value:
            raise ValueError(f"Param.{self.name}: an empty tuple has no C array (give None)")
        items = ", ".join(c_value(v, self.element) for v in value)
        return f"static const {C_TYPES[self.element]} {array_name}[{len(value)}] = {{{items}}};"

    def initialiser(self, value, array_name: str) -> str:
        """Its value in AfStageParam's initialiser."""
        if value is None:
            if not self.optional:
                raise ValueError(f"Param.{self.name}: None where its type is not optional")
            if self.sequence:
                return "NULL, 0"
            if self.element not in NONE_IN_C:
                raise ValueError(f"Param.{self.name}: no C value stands for None in a {self.element}")
            return NONE_IN_C[self.element]
        return f"{array_name}, {len(value)}" if self.sequence else c_value(value, self.element)


def _param_fields() -> list[CField]:
    """Every field of blocks.params.Param, in its order, as C holds it: a type of C_TYPES, or
    tuple[T, ...] of one, either optionally | None."""
    fields = []
    for field in dataclasses.fields(Param):
        # a string where the annotations are postponed; else the type itself ("float | None" as str())
        type_name = field.type if isinstance(field.type, str) else (
            field.type.__name__ if isinstance(field.type, type) else str(field.type))
        parts = [part.strip() for part in type_name.split("|")]
        optional = "None" in parts
        kinds = [part for part in parts if part != "None"]
        sequence = len(kinds) == 1 and TUPLE.fullmatch(kinds[0])
        element = sequence.group(1) if sequence else kinds[0] if len(kinds) == 1 else None
        if element not in C_TYPES:
            raise ValueError(f"Param.{field.name}: no C type for {type_name!r} (generate_tables.C_TYPES, "
                             "tuple[T, ...] of one, either | None)")
        c_name = field.name + "_value" if field.name in C_KEYWORDS else field.name
        fields.append(CField(field.name, c_name, element, bool(sequence), optional))
    return fields


def _identifier(name: str) -> str:
    if not name.isidentifier() or not name.isascii():
        raise ValueError(f"parameter, stage or profile name {name!r} is not a C identifier")
    return name


def _param_struct(type_name: str, leading: list[str], fields: list[CField]) -> list[str]:
    """The typedef of type_name: the leading members, then every field's (CField.members)."""
    members = leading + [member for field in fields for member in field.members()]
    return ["typedef struct {", *(f"    {member}" for member in members), f"}} {type_name};"]


def _param_table(array: str, type_name: str, params, fields: list[CField], leading=lambda p: []) -> list[str]:
    """static const type_name array[] with every Param of params, its leading values (leading(p))
    then its fields', after the static arrays of its sequences (array_<param>_<field>)."""
    names = {(p.name, f.name): f"{array}_{p.name}_{f.name}" for p in params for f in fields}
    lines = [text for p in params for f in fields
             if (text := f.array(getattr(p, f.name), names[p.name, f.name])) is not None]
    lines.append(f"static const {type_name} {array}[{len(params)}] = {{")
    for p in params:
        values = leading(p) + [f.initialiser(getattr(p, f.name), names[p.name, f.name]) for f in fields]
        lines.append(f"    {{{', '.join(values)}}},")
    lines.append("};")
    return lines


def header_text() -> str:
    """The text of af_params.h."""
    params = list(uses())
    all_stages = stages()
    fields = _param_fields()
    lines = [
        "/* af_params.h: generated by blocks/core/generate_tables.py from the Python tables",
        " * (blocks/tuning.py: METHODS, ESTIMATORS, uses; blocks.params.Param).",
        " * Do not edit: generate it again. */",
        "#ifndef AF_PARAMS_H",
        "#define AF_PARAMS_H",
        "",
        "#include <math.h>   /* NAN */",
        "#include <stddef.h> /* NULL */",
        "",
        "/* Every tuning parameter once, in the order of blocks.tuning.uses (the FMU's variables'); a value array of",
        " * AF_N_PARAMS doubles is indexed by AF_P_<name> (NaN: not given). */",
        f"#define AF_N_PARAMS {len(params)}",
        "",
        "/* tau_mag_guard unset: the heading guard's tightest tolerance in s.d. of the noise its low-pass leaves",
        " * (blocks.tuning.GUARD_NOISE_MARGIN) */",
        f"#define GUARD_NOISE_MARGIN {c_double(GUARD_NOISE_MARGIN)}",
        "/* the block of the heading's drift estimate's measure of the field heading's noise, in tau_heading",
        " * (blocks.tuning.DRIFT_BLOCK_TAUS) */",
        f"#define DRIFT_BLOCK_TAUS {c_double(DRIFT_BLOCK_TAUS)}",
        "/* the heading follows its drift rate's estimate once it is this many s.d. from 0",
        " * (blocks.tuning.DRIFT_SIGMAS) */",
        f"#define DRIFT_SIGMAS {c_double(DRIFT_SIGMAS)}",
        "",
        "enum {",
        *(f"    AF_P_{_identifier(name)} = {i}," for i, name in enumerate(params)),
        "};",
        "",
        "typedef struct {",
        "    const char *name;",
        "} AfParam;",
        "",
        "static const AfParam AF_PARAMS[AF_N_PARAMS] = {",
        *(f"    {{{c_string(name)}}}," for name in params),
        "};",
        "",
        "/* The stages that have tuning parameters: every method (blocks.tuning.METHODS,",
        " * in its order), then the gyro-offset and heading estimators. */",
        f"#define AF_N_METHODS {len(METHODS)}",
        "enum {",
        *(f"    AF_STAGE_{_identifier(name)} = {i}," for i, (name, *_) in enumerate(all_stages)),
        "    AF_N_STAGES",
        "};",
        "",
        "/* One parameter of a stage, field by field as blocks.params.Param (NaN where its default is",
        " * None; a tuple as its values and their count n_<name>, NULL where None), with its index",
        " * into the AF_N_PARAMS values. */",
        *_param_struct("AfStageParam", ["int index;"], fields),
        "",
        "typedef struct {",
        "    const char *name;  /* the method's name, or the estimator's C name */",
        "    const char *owner; /* as resolve_params (params.c) names it in messages */",
        "    const char *label; /* as blocks.pipeline.causal.split_params names it in messages */",
        "    int n_params;",
        "    const AfStageParam *params;",
        "} AfStage;",
        "",
    ]
    for name, _, _, stage_params in all_stages:
        if stage_params:
            lines += _param_table(f"AF_STAGE_PARAMS_{name}", "AfStageParam", stage_params, fields,
                                  lambda p: [f"AF_P_{p.name}"])
    lines += [
        "",
        "static const AfStage AF_STAGES[AF_N_STAGES] = {",
        *(f"    {{{c_string(name)}, {c_string(owner)}, {c_string(label)}, {len(ps)}, "
          f"{f'AF_STAGE_PARAMS_{name}' if ps else 'NULL'}}},"
          for name, owner, label, ps in all_stages),
        "};",
        "",
    ]
    lines += [
        "#endif",
        "",
    ]
    return "\n".join(lines)


def profiles_text() -> str:
    """The text of sim_profiles.h."""
    fields = _param_fields()
    lines = [
        "/* sim_profiles.h: generated by blocks/core/generate_tables.py from the Python table",
        " * (systems/simulation/profile_table.py: PROFILES, GRAVITY; blocks.params.Param).",
        " * Do not edit: generate it again. */",
        "#ifndef SIM_PROFILES_H",
        "#define SIM_PROFILES_H",
        "",
        "#include <math.h>   /* NAN */",
        "#include <stddef.h> /* NULL */",
        "",
        "/* The motion profiles, in the order of profile_table.py's PROFILES, and the most parameters one takes. */",
        f"#define SIM_N_PROFILES {len(PROFILES)}",
        f"#define SIM_PROFILE_MAX_PARAMS {max(len(params) for _, params in PROFILES.values())}",
        "",
        "/* One parameter of a profile, field by field as blocks.params.Param (NaN where its default is None; a",
        " * tuple as its values and their count n_<name>, NULL where None). */",
        *_param_struct("SimProfileParam", [], fields),
        "",
        "typedef struct {",
        "    const char *name;    /* the profile's, MotionProfile.fmu's value of profile */",
        "    const char *summary;",
        "    int n_params;",
        "    const SimProfileParam *params; /* in the order the profile takes them */",
        "} SimProfile;",
        "",
    ]
    for name, (_, params) in PROFILES.items():
        lines += _param_table(f"SIM_PROFILE_PARAMS_{_identifier(name)}", "SimProfileParam", params, fields)
    lines += [
        "",
        "static const SimProfile SIM_PROFILES[SIM_N_PROFILES] = {",
        *(f"    {{{c_string(name)}, {c_string(summary)}, {len(params)}, SIM_PROFILE_PARAMS_{name}}},"
          for name, (summary, params) in PROFILES.items()),
        "};",
        "",
        "/* gravity g, every profile's (m/s^2) */",
        *_param_table("SIM_PROFILE_GRAVITY", "SimProfileParam", (GRAVITY,), fields),
        "",
        "#endif",
        "",
    ]
    return "\n".join(lines)


def write_headers(folder) -> list[Path]:
    """af_params.h and sim_profiles.h written into folder (created if missing); returns their paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, text in ((HEADER, header_text()), (PROFILES_HEADER, profiles_text())):
        paths.append(folder / name)
        paths[-1].write_text(text, encoding="ascii")
    return paths


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python blocks/core/generate_tables.py DIR")
    print(*write_headers(sys.argv[1]), sep="\n")
