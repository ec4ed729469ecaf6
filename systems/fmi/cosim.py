"""A small co-simulation master for the project's SSP files, on fmpy's FMU2Slave API.

fmpy.ssp.simulate_ssp falls short here in two ways: it ignores the parameter bindings
inside the SSD (it takes one parameter set as an argument), and it passes values along
connections only after every component has stepped, so each connection delays by one
step and every connector starts at 0. This master reads the same SSD with fmpy, applies
its inline parameter values of every type (an Enumeration's by item name or value:
enumeration_value), and steps the components in the order of
their connections (Gauss–Seidel): in doStep(t, h) the estimator receives the sensor
samples of (t, t+h], exactly as the batch path consumes them. The steps run in C
(systems.fmi.stepping) where a C compiler is at hand, else in Python. cosimulate_libcosim runs
the same SSP in a second importer, independent of fmpy (libcosim).
"""
from __future__ import annotations

import contextlib
import math
import os
import shutil
import tempfile
from collections import defaultdict
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.ssp.ssd import read_ssd

from attitude_fmu.systems.fmi import stepping

_loaded = False  # whether this process has loaded an FMU's library


def load_slave(md, unzipdir, instance_name: str) -> FMU2Slave:
    """An FMU2Slave for an extracted FMU (pythonfmu FMUs: see fmus_loaded)."""
    global _loaded
    _loaded = True
    return FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                     instanceName=instance_name)


def enumeration_value(variable, value) -> int:
    """The integer value of an item of an Enumeration variable of fmpy's model description
    (the estimator's `method`, the motion's `profile`, ...), given by its name as the command
    line spells it, or by its value; ValueError naming the items if it has no such item."""
    items = {item.name: int(item.value) for item in variable.declaredType.items}
    if isinstance(value, str) and value in items:
        return items[value]
    if not isinstance(value, (str, bool)) and value in items.values():
        return int(value)
    raise ValueError(f"{variable.name} must be one of {', '.join(items)}; got {value!r}")


def start_values(model_description, values: dict) -> dict:
    """values (variable name → value) as an FMU takes them: each Enumeration's item name as its
    integer value (enumeration_value), the others as given; for fmpy.simulate_fmu's start_values."""
    variables = {v.name: v for v in model_description.modelVariables}
    return {name: enumeration_value(variables[name], value)
            if name in variables and variables[name].type == "Enumeration" else value
            for name, value in values.items()}


def set_value(fmu: FMU2Slave, variable, value) -> None:
    """Set a variable of fmpy's model description on an FMI 2.0 instance, by its type: a Real
    (float), an Integer (int), an Enumeration (its item name or value: enumeration_value), a
    Boolean (bool, or the text true/false) or a String."""
    vr = [variable.valueReference]
    if variable.type == "Enumeration":
        fmu.setInteger(vr, [enumeration_value(variable, value)])
    elif variable.type == "Integer":
        fmu.setInteger(vr, [int(value)])
    elif variable.type == "Boolean":
        fmu.setBoolean(vr, [value.lower() == "true" if isinstance(value, str) else bool(value)])
    elif variable.type == "String":
        fmu.setString(vr, [str(value)])
    else:
        fmu.setReal(vr, [float(value)])


def fmus_loaded() -> bool:
    """Whether this process loaded an FMU. pythonfmu's export library finalises its Python
    state from a library destructor, which can crash at interpreter shutdown after all
    work is done; processes that loaded FMUs end with os._exit once they have reported."""
    return _loaded


MAX_STEPS = 10_000_000  # communication steps of one cosimulate run (28 h at 0.01 s): the record is kept in memory


class _Component:
    """One instantiated FMU of the SSD with its variable references, extracted into unzipdir."""

    def __init__(self, element, ssp_dir: Path, unzipdir: Path):
        fmu_path = _source(element, ssp_dir)
        self.name = element.name
        try:
            self.md = read_model_description(fmu_path)
            self.unzipdir = extract(fmu_path, unzipdir=unzipdir)
        except Exception as exc:  # fmpy's refusals of an archive or its XML are plain Exceptions
            raise ValueError(f"component {element.name}: {element.source} is no FMU fmpy can read: "
                             f"{one_line(exc)}") from None
        self.variables = {v.name: v for v in self.md.modelVariables}
        cwd = os.getcwd()  # fmpy enters the binary's folder to load it, and stays there where that fails
        try:
            self.fmu = load_slave(self.md, self.unzipdir, element.name)
        except Exception as exc:  # a binary that does not load (another platform's, broken)
            os.chdir(cwd)
            raise RuntimeError(f"component {element.name}: its binary ({element.source}) failed to load: "
                               f"{one_line(exc)}") from None
        self.outputs = [v.name for v in self.md.modelVariables if v.causality == "output"]
        self.real_out = [n for n in self.outputs if self.variables[n].type == "Real"]
        self.bool_out = [n for n in self.outputs if self.variables[n].type == "Boolean"]
        self.real_out_vr = [self.variables[n].valueReference for n in self.real_out]
        self.bool_out_vr = [self.variables[n].valueReference for n in self.bool_out]
        self.inputs: list[tuple[str, str, str]] = []  # (own input, source component, source output)

    def start(self, parameters, start_time: float):
        """Instantiated, in Initialization Mode at start_time (s), its parameters set."""
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=start_time)
        self.fmu.enterInitializationMode()
        for p in parameters:  # an SSD's values are text (an Enumeration's: its item's value or name)
            variable = self.variable(p.name, "a parameter binding")
            set_value(self.fmu, variable, int(p.value) if p.type == "Integer" else p.value)
        self.input_vr = [self.variables[name].valueReference for name, _, _ in self.inputs]

    def output_values(self) -> list[float]:
        """Its Real and Boolean outputs (Booleans as 0 or 1), in the order real_out + bool_out."""
        values = list(self.fmu.getReal(self.real_out_vr))
        if self.bool_out_vr:
            values += [float(b) for b in self.fmu.getBoolean(self.bool_out_vr)]
        return values

    def variable(self, name: str, what: str, causality: str | None = None):
        """The variable name (of causality, where given) of fmpy's model description; ValueError naming
        the component, the variable and what named it (what) where it has none."""
        variable = self.variables.get(name)
        if variable is None or (causality is not None and variable.causality != causality):
            kind = f"{causality} variable" if causality else "variable"
            raise ValueError(f"component {self.name} has no {kind} {name!r} ({what} names it)")
        return variable

    def stop(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


MASTERS = ("gauss-seidel", "jacobi")


def cosimulate(ssp_path, stop_time: float, step_size: float, progress=None,
               master: str = "gauss-seidel") -> dict[str, np.ndarray]:
    """Run the SSP from 0 to stop_time (s) with a fixed step (s).

    master: "gauss-seidel" (the default) steps the components in the order of their connections at
    the times k·step_size, each taking its sources' outputs of the same step. "jacobi" steps as
    strict masters do (OMSimulator's and libcosim's fixed-step algorithms): in Initialization Mode
    each component's inputs are its sources' outputs read there (in the order of the connections);
    every step then hands on the outputs of the step before (a component k connections from a
    source sees it k steps late); time is summed step by step, and a last step of the shortfall
    (picoseconds) reaches stop_time.

    Returns "time" (end of each step) and every output as "component.variable", one
    value per step. progress(fraction) is called about every 1 % when given. ValueError, in
    one line, for a stop time or step that is not finite and positive or makes more than
    MAX_STEPS steps, a file that is no SSP fmpy reads, a component whose source is not an
    FMU inside the SSP (an absolute path or one leaving it is refused, never loaded), and bad
    connections or parameters; RuntimeError for a component that fails to load or step.
    Nothing extracted outlives the call.
    """
    if master not in MASTERS:
        raise ValueError(f"the master must be one of {', '.join(MASTERS)}, got {master!r}")
    n = step_count(stop_time, step_size)
    try:
        ssd = read_ssd(str(ssp_path))
    except Exception as exc:  # zipfile's, lxml's and fmpy's own (a plain Exception) refusals
        raise ValueError(f"{ssp_path} is no SSP fmpy can read: {one_line(exc)}") from None
    with tempfile.TemporaryDirectory(prefix="attitude_fmu_ssp_") as tmp:
        return _run_ssd(ssd, ssp_path, Path(tmp), n, step_size, progress, master == "jacobi", stop_time)


def step_count(stop_time: float, step_size: float) -> int:
    """The communication steps from 0 to stop_time (s) of step_size (s); ValueError unless both are finite and
    positive and they make 1 to MAX_STEPS steps."""
    for name, value in (("stop time", stop_time), ("step size", step_size)):
        if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)) \
                or not math.isfinite(value) or value <= 0:
            raise ValueError(f"the {name} must be a finite positive number of seconds, got {value!r}")
    n = round(stop_time / step_size)
    if not 1 <= n <= MAX_STEPS:
        raise ValueError(f"a stop time of {stop_time!r} s in steps of {step_size!r} s makes {n} steps; "
                         f"cosimulate runs 1 to {MAX_STEPS}")
    return n


def _source(element, ssp_dir: Path) -> Path:
    """The FMU file of the SSD's component element, inside the extracted SSP ssp_dir; ValueError for a
    source that is absolute, leaves the SSP, or names no file in it."""
    source = str(element.source or "")
    path = (ssp_dir / source).resolve()
    if Path(source).is_absolute() or "\\" in source or not path.is_relative_to(ssp_dir.resolve()):
        raise ValueError(f"component {element.name}: its source {source!r} is outside the SSP; an SSP's "
                         "components are FMUs inside it (resources/NAME.fmu)")
    if not path.is_file():
        raise ValueError(f"component {element.name}: the SSP holds no file {source!r}")
    return path


def one_line(exc: BaseException) -> str:
    """An exception as one line of at most 300 characters: its type, and its message where it has one."""
    message = " ".join(str(exc).split())[:300]
    return f"{type(exc).__name__}" + (f": {message}" if message else "")


def _run_ssd(ssd, ssp_path, tmp: Path, n: int, step_size: float, progress, jacobi: bool = False,
             stop_time: float = 0.0) -> dict[str, np.ndarray]:
    """cosimulate's run of the SSD read from ssp_path, extracted into tmp, for n steps of step_size (jacobi:
    Jacobi steps with time summed to stop_time, _jacobi_steps): its record."""
    ssp_dir = tmp / "ssp"
    try:
        extract(str(ssp_path), unzipdir=ssp_dir)
    except Exception as exc:
        raise ValueError(f"{ssp_path} cannot be extracted: {one_line(exc)}") from None
    components = {}
    try:
        for k, element in enumerate(ssd.system.elements):
            components[element.name] = _Component(element, ssp_dir, tmp / f"component-{k}")
        for c in ssd.system.connections:
            _connect(components, c)
        order = _stepping_order(components)
        for element in ssd.system.elements:
            params = [p for b in element.parameterBindings for s in b.parameterValues for p in s.parameters]
            try:
                components[element.name].start(params, 0.0)
            except FMICallException as exc:
                raise RuntimeError(f"component {element.name} failed to initialise: {exc}") from None
        # the record's columns: each component's Real outputs, then its Boolean ones, in stepping order
        columns = {f"{c.name}.{v}": (c, v) for c in order for v in c.real_out + c.bool_out}
        _initialise(order, jacobi)
        if jacobi:
            times, values = _jacobi_steps(order, list(columns), stop_time, step_size, n, progress)
        else:
            times, values = (np.arange(n) + 1) * step_size, _steps(order, list(columns), n, step_size, progress)
        record = {name: values[:, j].astype(bool) if v in c.bool_out else values[:, j]
                  for j, (name, (c, v)) in enumerate(columns.items())}
        record["time"] = times
        return record
    finally:
        for comp in components.values():
            with contextlib.suppress(Exception):  # an instance that never started has nothing to free
                comp.stop()


def _connect(components: dict, c) -> None:
    """The connection c of the SSD: its start an output of a component, its end an input of another;
    ValueError naming what is missing."""
    where = f"the connection {c.startElement}.{c.startConnector} -> {c.endElement}.{c.endConnector}"
    for element in (c.startElement, c.endElement):
        if element not in components:
            raise ValueError(f"{where} names a component the SSD does not have: {element!r}")
    source = components[c.startElement]
    if source.variable(c.startConnector, where, "output").type not in ("Real", "Boolean"):
        raise ValueError(f"{where}: {c.startElement}.{c.startConnector} is neither Real nor Boolean")
    components[c.endElement].variable(c.endConnector, where, "input")
    components[c.endElement].inputs.append((c.endConnector, c.startElement, c.startConnector))


def _initialise(order, jacobi: bool) -> None:
    """Every component out of Initialization Mode; for a Jacobi master, each one's inputs first set to its
    sources' outputs read in Initialization Mode, in stepping order, as OMSimulator does before
    fmi2ExitInitializationMode."""
    by_name = {c.name: c for c in order}
    for stage in ("inputs", "exit") if jacobi else ("exit",):
        for comp in order:
            try:
                if stage == "exit":
                    comp.fmu.exitInitializationMode()
                elif comp.inputs:
                    values = {src: dict(zip(by_name[src].real_out + by_name[src].bool_out,
                                            by_name[src].output_values())) for _, src, _ in comp.inputs}
                    comp.fmu.setReal(comp.input_vr, [values[src][out] for _, src, out in comp.inputs])
            except FMICallException as exc:
                raise RuntimeError(f"component {comp.name} failed to initialise: {exc}") from None


def _jacobi_steps(order, columns, stop_time: float, h: float, n: int, progress) -> tuple[np.ndarray, np.ndarray]:
    """Jacobi steps (cosimulate's master "jacobi") from 0 of h seconds, time summed, the last one to stop_time:
    (the end of each step, the record of the outputs "component.variable" after it, Booleans as 0 or 1)."""
    where = {name: j for j, name in enumerate(columns)}
    before = np.empty(len(columns))
    for comp in order:
        before[[where[f"{comp.name}.{v}"] for v in comp.real_out + comp.bool_out]] = comp.output_values()
    sources = {comp.name: [where[f"{src}.{out}"] for _, src, out in comp.inputs] for comp in order}
    places = {comp.name: [where[f"{comp.name}.{v}"] for v in comp.real_out + comp.bool_out] for comp in order}
    record, times, t, k = np.empty((n + 1, len(columns))), np.empty(n + 1), 0.0, 0
    while t < stop_time and k <= n:  # summed, the time falls short of stop_time by picoseconds: one step more
        end = min(t + h, stop_time)
        for comp in order:
            if comp.inputs:
                comp.fmu.setReal(comp.input_vr, list(before[sources[comp.name]]))
            try:
                comp.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=end - t)
            except FMICallException as exc:
                raise RuntimeError(f"component {comp.name} failed at t = {t!r} s over {end - t!r} s: {exc}") from None
            record[k, places[comp.name]] = comp.output_values()
        before, times[k], t, k = record[k], end, end, k + 1
        if progress is not None and k % max(1, n // 100) == 0:
            progress(k / (n + 1))
    return times[:k], record[:k]


def _steps(order, columns, n: int, h: float, progress) -> np.ndarray:
    """n steps of h seconds from 0 of the components in order (Gauss–Seidel): an n × len(columns)
    record of the outputs "component.variable" (Booleans as 0 or 1), by the C loop
    (systems.fmi.stepping) in chunks of about 1 %, or, without a C compiler, by _python_steps."""
    where = {name: j for j, name in enumerate(columns)}
    record = np.empty((n, len(columns)))
    lib = stepping.library()
    if lib is None:
        return _python_steps(order, where, record, h, progress)
    stepper = stepping.Stepper(lib, [
        (c.fmu, c.input_vr, [where[f"{src}.{out}"] for _, src, out in c.inputs], c.real_out_vr,
         where[f"{c.name}.{c.real_out[0]}"] if c.real_out else 0, c.bool_out_vr,
         where[f"{c.name}.{c.bool_out[0]}"] if c.bool_out else 0) for c in order])
    chunk = max(1, n // 100)
    for first in range(0, n, chunk):
        done, failed, status = stepper.run(record[first:first + chunk], 0.0, h, first)
        if failed is not None:
            raise RuntimeError(f"component {order[failed].name} failed at t = {(first + done) * h:g} s: "
                               f"status {status} (its log above says why)")
        if progress is not None:
            progress(first / n)
    return record


def _python_steps(order, where: dict, record: np.ndarray, h: float, progress) -> np.ndarray:
    """stepping.c's loop in Python, through fmpy."""
    n = len(record)
    for k in range(n):
        t = k * h
        for comp in order:
            if comp.inputs:
                comp.fmu.setReal(comp.input_vr, [record[k, where[f"{src}.{out}"]] for _, src, out in comp.inputs])
            try:
                comp.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            except FMICallException as exc:
                raise RuntimeError(f"component {comp.name} failed at t = {t:g} s: {exc}") from None
            for name, value in zip(comp.real_out + comp.bool_out, comp.output_values()):
                record[k, where[f"{comp.name}.{name}"]] = value
        if progress is not None and k % max(1, n // 100) == 0:
            progress(k / n)
    return record


def cosimulate_libcosim(ssp_path, stop_time: float, step_size: float, progress=None) -> dict[str, np.ndarray]:
    """Run the SSP with libcosim (Open Simulation Platform; libcosimpy, CPython >= 3.11):
    an importer independent of fmpy, with its own SSP reader, FMI Library, and a
    fixed-step master in which each connection delays by one step and inputs begin at
    their start values. Returns, as cosimulate does, "time" and every input and output as
    "component.variable", one value per step (time kept in integer nanoseconds)."""
    try:
        from libcosimpy.CosimEnums import CosimVariableCausality as Causality
        from libcosimpy.CosimEnums import CosimVariableType as Type
        from libcosimpy.CosimExecution import CosimExecution
        from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
        from libcosimpy.CosimObserver import CosimObserver
    except ImportError:
        raise RuntimeError("the libcosim master needs libcosimpy: pip install libcosimpy (CPython >= 3.11)") from None
    n = step_count(stop_time, step_size)
    log_output_level(CosimLogLevel.WARNING)
    global _loaded
    _loaded = True
    try:
        ex = CosimExecution.from_ssp_file(str(ssp_path), int(round(step_size * 1e9)))
    except AssertionError:
        raise RuntimeError(f"libcosim cannot load {ssp_path} (its log above says why)") from None
    observer = CosimObserver.create_last_value()
    ex.add_observer(observer)
    reads = []  # (component index, reader, references, record names, dtype)
    for slave in ex.slave_infos():
        variables = [v for v in ex.slave_variables(slave.index)
                     if v.causality in (Causality.INPUT.value, Causality.OUTPUT.value)]
        for kind, reader, dtype in ((Type.REAL, observer.last_real_values, float),
                                    (Type.BOOLEAN, observer.last_boolean_values, bool)):
            chosen = [v for v in variables if v.type == kind.value]
            if chosen:
                reads.append((slave.index, reader, [v.reference for v in chosen],
                              [f"{slave.name.decode()}.{v.name.decode()}" for v in chosen], dtype))
    record = {name: np.empty(n, dtype=dtype) for *_, names, dtype in reads for name in names}
    for k in range(n):
        if not ex.step():
            raise RuntimeError(f"libcosim failed at t = {k * step_size:g} s (its log above says why)")
        for index, reader, references, names, _ in reads:
            for name, value in zip(names, reader(index, references)):
                record[name][k] = value
        if progress is not None and k % max(1, n // 100) == 0:
            progress(k / n)
    record["time"] = (np.arange(n) + 1) * step_size
    return record


def _stepping_order(components: dict) -> list:
    """Components sorted so that every one steps after the components feeding it."""
    feeds = defaultdict(set)
    for comp in components.values():
        for _, src, _ in comp.inputs:
            feeds[comp.name].add(src)
    order, done = [], set()
    while len(order) < len(components):
        ready = [c for c in components.values() if c.name not in done and feeds[c.name] <= done]
        if not ready:
            raise ValueError("the SSP's connections form a loop; this master steps acyclic diagrams only")
        for comp in ready:
            order.append(comp)
            done.add(comp.name)
    return order


class FmuRunner:
    """One FMU driven step by step with fmpy: parameters at initialisation, then
    step(inputs) → outputs. reset() restarts it with the same parameters (fmi2Reset)."""

    def __init__(self, fmu_path, parameters: dict | None = None, inputs=(), outputs=(), logging: bool = False):
        self.md = read_model_description(str(fmu_path))
        self.variables = {v.name: v for v in self.md.modelVariables}
        self.unzipdir = extract(str(fmu_path))
        self.fmu = load_slave(self.md, self.unzipdir, Path(fmu_path).stem)
        self.parameters = dict(parameters or {})
        self.input_vr = [self.variables[n].valueReference for n in inputs]
        self.output_vr = [self.variables[n].valueReference for n in outputs]
        self.valid_vr = [self.variables["valid"].valueReference] if "valid" in self.variables else []
        self.time = 0.0
        self.fmu.instantiate(loggingOn=logging)
        try:
            self._initialise()
        except FMICallException:  # fmi2Error: the instance may only be freed
            self.fmu.freeInstance()
            shutil.rmtree(self.unzipdir, ignore_errors=True)
            raise

    def _initialise(self):
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        for name, value in self.parameters.items():
            set_value(self.fmu, self.variables[name], value)
        self.fmu.exitInitializationMode()
        self.time = 0.0

    def step(self, inputs, h: float):
        """Set inputs, doStep(time, h), return (outputs, valid or None)."""
        self.fmu.setReal(self.input_vr, [float(v) for v in inputs])
        self.fmu.doStep(currentCommunicationPoint=self.time, communicationStepSize=h)
        self.time += h
        valid = bool(self.fmu.getBoolean(self.valid_vr)[0]) if self.valid_vr else None
        return np.array(self.fmu.getReal(self.output_vr)), valid

    def run(self, inputs: np.ndarray, h: float):
        """Step through the rows of inputs (N×len(inputs)); outputs N×len(outputs), valid N."""
        out = np.empty((len(inputs), len(self.output_vr)))
        valid = np.empty(len(inputs), dtype=bool)
        for k, row in enumerate(inputs):
            out[k], valid[k] = self.step(row, h)
        return out, valid

    def reset(self):
        self.fmu.reset()
        self._initialise()

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()
        shutil.rmtree(self.unzipdir, ignore_errors=True)
