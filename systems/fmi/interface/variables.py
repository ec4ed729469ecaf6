"""The FMUs' variables: one table per interface, a row per variable (name, type, causality,
variability, initial, unit, start value, description, value reference).

Every model description of an interface is written from its table
(systems.fmi.interface.model_description): the pythonfmu FMU registers its variables from it
(fmu_support.ProjectSlave), the native FMU's modelDescription.xml and C header are
generated from it by the build (systems/fmi/interface/generate.py). So one FMU can take the other's place
in an SSP or a master's script: same names, causalities, units, start values and value
references. Only the standard library is imported (and blocks/tuning.py): the build runs it.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from functools import cache

from attitude_fmu.blocks.tuning import METHODS, uses
from attitude_fmu.systems.fmi.interface.escaping import fmi_name

# the sample conventions, as blocks.stages.timing (the C core's stages/timing.c) lists them
GYR_SAMPLES, ACC_SAMPLES = ("mean", "point"), ("point", "mean")

REAL, INTEGER, BOOLEAN, STRING, ENUMERATION = "Real", "Integer", "Boolean", "String", "Enumeration"
IN, OUT, PAR = "input", "output", "parameter"

# FMI unit name → SI base-unit exponents (FMI 2.0 BaseUnit attributes); None for the
# noise densities per √Hz, whose half-integer exponents FMI 2.0 cannot state
UNITS = {
    "s": {"s": 1},
    "Hz": {"s": -1},
    "m": {"m": 1},
    "rad": {"rad": 1},
    "deg": {"rad": 1, "factor": 0.017453292519943295},
    "rad/s": {"rad": 1, "s": -1},
    "1/s": {"s": -1},
    "1/s2": {"s": -2},
    "rad/s/sqrt(Hz)": None,
    "m/s/sqrt(Hz)": None,
    "m/s2/sqrt(Hz)": None,
    "m/s2": {"m": 1, "s": -2},
    "uT": {"kg": 1, "s": -2, "A": -1, "factor": 1e-6},
    "uT/sqrt(Hz)": None,
    "1": {},
}
# FMI unit name → (display unit, factor: display value per value): angles shown in degrees
DISPLAY_UNITS = {"rad": ("deg", 57.29577951308232)}
# FMI unit name → the physical quantity of the Real variables of that unit (their declared type)
QUANTITIES = {"rad": "Angle", "rad/s": "AngularVelocity", "m/s2": "Acceleration", "uT": "MagneticFluxDensity",
              "s": "Time", "m": "Length", "Hz": "Frequency"}


def fmi_unit(unit: str) -> str:
    """The FMI unit name of a unit as the project documents it ("m/s²" → "m/s2", "√Hz" → "sqrt(Hz)")."""
    name = unit.replace("√Hz", "sqrt(Hz)").replace("²", "2")
    if name not in UNITS:
        raise ValueError(f"unit {unit!r} has no FMI definition in systems.fmi.interface.variables.UNITS")
    return name


def element_names(name: str, dimensions) -> list[str]:
    """The names of an array's elements, row by row, 0-based as numpy: A[0,0], A[0,1], …"""
    return [f"{name}[{','.join(map(str, index))}]" for index in itertools.product(*map(range, dimensions))]


@dataclass(frozen=True)
class Variable:
    """One FMI variable. type: REAL, INTEGER, BOOLEAN, STRING or ENUMERATION; causality: IN, OUT
    or PAR; variability and initial as FMI 2.0 spells them (initial None: not stated); unit: an
    FMI unit name of UNITS (Real only); items: an Enumeration's item names, whose values are
    1, 2, …, n in that order (its start is one of those values); dimensions: an FMI 3.0 array's
    (a Real of size values, start a tuple of them, row-major; its elements hold the value
    references value_reference … value_reference + size − 1 within the FMU, as scalars
    name[i,j] do in FMI 2.0)."""

    name: str
    type: str
    causality: str
    variability: str
    start: float | int | bool | str
    description: str
    value_reference: int
    unit: str | None = None
    initial: str | None = None
    items: tuple[str, ...] = ()
    dimensions: tuple[int, ...] = ()

    @property
    def size(self) -> int:
        """The values it holds: 1, or an array's elements."""
        return math.prod(self.dimensions)

    def elements(self) -> list[tuple[str, float]]:
        """An array's elements as scalars: (name[i,j], start) row by row; a scalar's itself."""
        if not self.dimensions:
            return [(self.name, self.start)]
        return list(zip(element_names(self.name, self.dimensions), self.start))

    @property
    def declared_type(self) -> str:
        """The name of an Enumeration's type in the model description: its name in CamelCase."""
        return "".join(part.capitalize() for part in self.name.split("_"))


def item_value(variable: Variable, name: str) -> int:
    """The value (1, 2, …) of the item name of an Enumeration variable; ValueError naming the
    allowed items if it has no such item."""
    if name not in variable.items:
        allowed = ", ".join(variable.items) or "none: not an Enumeration"
        raise ValueError(f"{variable.name} must be one of {allowed}; got {name!r}")
    return variable.items.index(name) + 1


def items_text(variable: Variable) -> str:
    """An Enumeration's items as messages list them: "1 mag, 2 gyro"."""
    return ", ".join(f"{value} {name}" for value, name in enumerate(variable.items, 1)) or "none: not an Enumeration"


def item_name(variable: Variable, value: int) -> str:
    """The item name of the value (1, 2, …) of an Enumeration variable; ValueError naming the
    items if it has no item of that value."""
    if not (isinstance(value, int) and 1 <= value <= len(variable.items)):
        raise ValueError(f"{variable.name} must be one of its items ({items_text(variable)}), got {value!r}")
    return variable.items[value - 1]


class Table(list):
    """Variables in the order of their value references 0, 1, 2, …; each helper appends
    its rows and returns them."""

    def add(self, name, type_, causality, variability, start, description, unit=None, initial=None,
            items=(), dimensions=()) -> list[Variable]:
        """A row; its value reference the next free one (an array holds one per element). ValueError
        for a name outside FMI's structured naming (escaping.fmi_name)."""
        fmi_name(name)
        if unit is not None and unit not in UNITS:
            raise ValueError(f"unit {unit!r} has no definition in systems.fmi.interface.variables.UNITS")
        if dimensions and (type_ != REAL or len(start) != math.prod(dimensions)):
            raise ValueError(f"{name}: an array is a Real with a start value per element")
        self.append(Variable(name, type_, causality, variability, start, description,
                             sum(v.size for v in self), unit, initial, tuple(items), tuple(dimensions)))
        return self[-1:]

    def real(self, name, start, unit, description, causality, calculated=False) -> list[Variable]:
        """A Real input, output or (fixed) parameter. Outputs start exact at start, held until a step sets
        them; calculated: the FMU computes them at the start time in Initialization Mode (initial
        "calculated": the model description gives no start, the FMU's own value before then is start)."""
        initial = ("calculated" if calculated else "exact") if causality == OUT else None
        return self.add(name, REAL, causality, "fixed" if causality == PAR else "continuous", float(start),
                        description, unit, initial)

    def vector(self, prefix, start, unit, description, causality, components="xyz", calculated=False) -> list[Variable]:
        """prefix_<c> for each component c; description may use {c}."""
        return [v for c, value in zip(components, start)
                for v in self.real(f"{prefix}_{c}", value, unit, description.format(c=c), causality, calculated)]

    def parameter(self, name, start, description, type_=INTEGER) -> list[Variable]:
        """A fixed Integer or Boolean parameter."""
        return self.add(name, type_, PAR, "fixed", start, description)

    def choice(self, name, items, start, description) -> list[Variable]:
        """A fixed Enumeration parameter: one of the item names (as the command line spells
        them), start the one it starts at; the description lists them."""
        items = tuple(items)
        if start not in items or len(set(items)) != len(items):
            raise ValueError(f"{name}: start {start!r} must be one of the distinct items {items}")
        return self.add(name, ENUMERATION, PAR, "fixed", items.index(start) + 1,
                        f"{description} (items: {', '.join(items)})", items=items)

    def boolean_output(self, name, start, description) -> list[Variable]:
        return self.add(name, BOOLEAN, OUT, "discrete", bool(start), description, initial="exact")

    def extend_from(self, rows) -> list[Variable]:
        """Rows of another table, which must continue this one's value references."""
        rows = list(rows)
        for k, v in enumerate(rows):
            if v.value_reference != len(self) + k:
                raise ValueError(f"{v.name} has value reference {v.value_reference}, not {len(self) + k}")
        self.extend(rows)
        return rows


def tuning_parameters() -> dict:
    """Every method's tuning parameters and those of the gyro-offset and heading
    estimators, once each: name → (FMI unit, description, start value).

    The start value is the default where every stage with the name has that one default.
    Where the stages' defaults differ, it is the first stage's default that is a number;
    where none has a number (unset: the default is derived from other parameters or from
    the data, or the stage does without), it is a value outside the parameter's range: 0, or
    -1 where 0 is in it. Either way a value equal to the start means "unset": each stage that
    runs takes its own default when the FMU is initialised, as the descriptions say (so does
    NaN)."""
    params = {}
    for name, stages in uses().items():
        first = stages[0][1]
        defaults = {p.default for _, p in stages}
        if len(defaults) == 1 and first.default is not None:
            params[name] = (fmi_unit(first.unit), f"{first.doc}; default {first.default:g}", first.default)
            continue
        numbers = [p.default for _, p in stages if p.default is not None]
        start = numbers[0] if numbers else (-1.0 if first.allow_zero else 0.0)
        if defaults == {None}:
            doc = f"{first.doc}; {start:g} (the start value): unset, taken when the FMU is initialised"
        else:
            each = "; ".join(f"{owner}: {'unset' if p.default is None else format(p.default, 'g')}"
                             for owner, p in stages)
            doc = f"{first.doc}; {start:g} (the start value): the default of the stage that runs ({each})"
        params[name] = (fmi_unit(first.unit), doc, start)
    return params


@cache
def attitude_estimator() -> tuple[Variable, ...]:
    """AttitudeEstimator's interface (fmu_src/AttitudeEstimator.py says what each step does)."""
    t = Table()
    t.vector("gyr", (0.0, 0.0, 0.0), "rad/s", "gyro {c}, mean rate over the step (gyr_samples mean) "
             "or the rate at its end (point)", IN)
    t.vector("acc", (0.0, 0.0, 9.81), "m/s2", "specific force {c} at the end of the step (acc_samples point) "
             "or its mean over the step (mean)", IN)
    t.vector("mag", (0.0, 0.0, 0.0), "uT", "magnetic field {c}; all 0: no magnetometer (heading from the gyro); "
             "NaN: no sample this step", IN)
    t.vector("q", (1.0, 0.0, 0.0, 0.0), "1", "orientation quaternion {c}, sensor -> earth (ENU)", OUT, "wxyz")
    t.vector("g", (0.0, 0.0, 1.0), "1", "estimated unit up-vector {c}, sensor coordinates", OUT)
    for name in ("roll", "pitch", "yaw"):
        t.real(name, 0.0, "rad", f"{name} (Z-Y-X Euler angles of q; derived output)", OUT)
    t.vector("gyr_offset", (0.0, 0.0, 0.0), "rad/s", "estimated gyro offset {c} (gyro_offset on; else 0)", OUT)
    t.vector("mag_offset", (0.0, 0.0, 0.0), "uT", "estimated hard-iron offset {c} of the magnetometer "
             "(heading mag; 0 until one is proven)", OUT)
    t.real("mag_delay_used", 0.0, "s", "the magnetometer's delay behind the gyro the heading allows for "
           "(the parameter mag_delay, or its online estimate: 0 until one is taken)", OUT)
    t.boolean_output("valid", False, "an estimate is available and the last inputs were finite")
    t.choice("method", METHODS, "wiener", "estimator")
    t.choice("heading", ("mag", "gyro"), "mag", "heading source: mag (magnetometer, hard iron fitted, guarded "
             "against disturbances) or gyro")
    t.choice("gyro_offset", ("on", "off"), "on", "on (default, as attitude estimate): estimate and remove the gyro "
             "offset (at rest and while moving); off: for a gyro without offset")
    t.real("Ts", 0.01, "s", "sample time of the estimator: a communication step runs the samples of its grid "
           "(start time + k·Ts) it reaches, its inputs held", PAR)
    t.choice("gyr_samples", GYR_SAMPLES, "mean", "mean: gyr is the mean rate over the step (the FMI convention of "
             "MotionProfile and ImuSensor); point: the rate at the step's end (most models' outputs), "
             "averaged with the last one")
    t.choice("acc_samples", ACC_SAMPLES, "point", "point: acc is the specific force at the step's end (the FMI "
             "convention of MotionProfile and ImuSensor); mean: its mean over the step (a sensor that "
             "averages it as the gyro), turned to the step's end by half the step's rotation")
    t.real("latency", 0.0, "s", "the IMU's delay behind the motion (its filters' group delay, gyr taken as the "
           "mean rate over the step); q and g are carried forward over it with the gyro", PAR)
    for name, (unit, doc, start) in tuning_parameters().items():
        t.real(name, start, unit, doc, PAR)
    return tuple(t)
