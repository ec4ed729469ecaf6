"""FMI plumbing shared by the project's pythonfmu FMUs: registration of their variables from
a table (systems.fmi.interface.variables) whose model description they write, FMU states, and the check
that the attitude_fmu code a process runs is the FMU's own (systems.fmi.carried_code).

The models' equations live in `blocks/` and `systems/`; an FMU here only maps FMI
variables onto them.
"""
from __future__ import annotations

import copy
import importlib
import pickle
from xml.etree.ElementTree import Element

from pythonfmu import Boolean, Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Integer, Real, String
from pythonfmu.enums import Fmi2Status

from attitude_fmu.systems.fmi.carried_code import foreign_code
from attitude_fmu.systems.fmi.interface.escaping import xml_tree
from attitude_fmu.systems.fmi.interface.model_description import (
    default_experiment,
    metadata,
    model_structure,
    model_variables,
    type_definitions,
    unit_definitions,
)
from attitude_fmu.systems.fmi.interface.variables import BOOLEAN, ENUMERATION, INTEGER, REAL, STRING, Table, item_name

INTERNAL_STATE = " internal"  # key of a saved FMU state's model part (no variable name has a space)


class ProjectSlave(Fmi2Slave):
    """Fmi2Slave with units and helpers; subclasses register their variables and build
    their model from the parameters in initialise().

    fmi2GetFMUstate saves the variables and copies of the attributes named in
    internal_state (the model's state between steps) and the error; fmi2SetFMUstate
    restores them, as often as the master rolls back (canGetAndSetFMUstate). A saved
    state serialises with pickle (canSerializeFMUstate): the bytes come from this FMU
    and go back to it, and like the FMU's code they are to be trusted."""

    internal_state: tuple[str, ...] = ()

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.table = Table()  # the variables registered, by value reference
        self.error = foreign_code(self.resources)
        self.start_time = 0.0  # s: where a sample time's grid begins (blocks.stages.timing.grid_samples)

    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        self.start_time = float(start_time)

    def _get_fmu_state(self) -> dict:
        state = super()._get_fmu_state()
        state[INTERNAL_STATE] = copy.deepcopy({name: getattr(self, name) for name in ("error", *self.internal_state)})
        return state

    @staticmethod
    def _fmu_state_to_bytes(state: dict) -> bytes:
        return pickle.dumps(state)

    @staticmethod
    def _fmu_state_from_bytes(data: bytes) -> dict | None:
        try:
            return pickle.loads(data)
        except Exception:  # never raise (see fail); _set_fmu_state refuses it
            return None

    def _set_fmu_state(self, state: dict | None) -> None:
        if not (isinstance(state, dict) and INTERNAL_STATE in state):
            self.log("fmi2SetFMUstate: not a state this FMU saved or serialised; state unchanged", Fmi2Status.error)
            return
        state = dict(state)
        internal = copy.deepcopy(state.pop(INTERNAL_STATE))  # the saved state stays as saved
        super()._set_fmu_state(state)
        for name, value in internal.items():
            setattr(self, name, value)

    initialising = False  # in Initialization Mode

    def enter_initialization_mode(self):
        self.initialising = True

    def exit_initialization_mode(self):
        self.initialising = False
        if self.error is not None:
            self.fail(self.error)
            return
        self.initialise()
        if self.error is None:
            for name, value in (self.start_values() or {}).items():
                setattr(self, name, value)

    def initialise(self):
        """Build the model from the parameters; an invalid one: fail(message)."""

    def start_values(self) -> dict[str, float] | None:
        """The calculated outputs (initial "calculated": a motion's or a sensor's, which a Jacobi master
        reads before the first step) at the start time, by name, from the parameters and inputs as they
        are, the FMU's state left as it is; None where the parameters are refused (nothing logged:
        fmi2ExitInitializationMode says why) or the FMU has none. Read by each get in Initialization
        Mode and set at its exit, as the native FMUs do (fmu_src/fmi2/fmi2_model.h: start)."""
        return None

    def _calculated(self, name: str) -> float:
        """A calculated output's getter: in Initialization Mode its value at the start time, later the
        attribute."""
        if self.initialising and self.error is None:
            values = self.start_values()
            if values is not None:
                return values[name]
        return getattr(self, name)

    def to_xml(self, model_options=None) -> Element:
        """pythonfmu's model description with the variables' sections, the default experiment and
        the metadata (version: the project's) written from the table, as the native FMUs' are."""
        # the build's module, which the FMU does not carry: imported by name, as the build only writes
        # the model description (systems.fmi.build.carried_files follows import statements)
        project_version = importlib.import_module("attitude_fmu.build_fmu").project_version
        root = super().to_xml(model_options or {})
        for name in ("ModelVariables", "ModelStructure", "DefaultExperiment"):
            if root.find(name) is not None:
                root.remove(root.find(name))
        root.attrib.update(metadata(project_version()))
        at = list(root).index(root.find("CoSimulation")) + 1
        root.insert(at, unit_definitions(self.table))
        root.insert(at + 1, type_definitions(self.table))
        root.insert(list(root).index(root.find("LogCategories")) + 1, default_experiment())
        root.append(model_variables(self.table))
        root.append(model_structure(self.table))
        return xml_tree(root, f"{type(self).__name__}'s modelDescription.xml")

    def item(self, name: str) -> str:
        """The item name of the Enumeration variable name's value (sets are checked: item_name
        refuses a value of an FMU state from elsewhere with ValueError)."""
        return item_name(next(v for v in self.table if v.name == name), getattr(self, name))

    def _set_item(self, variable, value) -> None:
        """An Enumeration's setter: a value none of its items have is refused with an error logged
        (fmi2Error through the guard) and the value kept, as the native FMUs do."""
        try:
            item_name(variable, value)
        except ValueError as exc:
            self.log(f"fmi2SetInteger: {exc}", Fmi2Status.error)
            return
        setattr(self, variable.name, value)

    def register(self, rows) -> None:
        """Register rows of self.table (systems.fmi.interface.variables.Variable) with pythonfmu, each
        held in the attribute of its name, which starts at its start value."""
        for v in rows:
            setattr(self, v.name, v.start)
            extra = {"initial": Fmi2Initial[v.initial]} if v.initial else {}
            if v.type == ENUMERATION:  # pythonfmu has no Enumeration: an Integer whose sets are checked
                extra["setter"] = lambda value, v=v: self._set_item(v, value)
            if v.initial == "calculated":
                extra["getter"] = lambda v=v: self._calculated(v.name)
            self.register_variable(_PYTHONFMU_TYPES[v.type](
                v.name, causality=Fmi2Causality[v.causality], variability=Fmi2Variability[v.variability],
                description=v.description, **extra), nested=False)
            if self.vars[v.value_reference].name != v.name:
                raise ValueError(f"{v.name}: pythonfmu numbers it otherwise than the table")

    def register_table(self, rows) -> None:
        """Register every row of another table (an interface of systems.fmi.interface.variables)."""
        self.register(self.table.extend_from(rows))

    error = None  # the message of an invalid configuration or of foreign code, once one was found

    def fail(self, message: str) -> bool:
        """Log an error and remember it; every later doStep logs it again.

        The FMU's binary (fmi2_guard.c) ends a call that logged an error in fmi2Error.
        Never raise: pythonfmu turns a Python exception into fmi2Fatal and releases the
        instance's Python objects twice, corrupting the interpreter the FMU runs in.
        Returns False, doStep's value for fmi2Discard (what an FMU without the guard returns)."""
        self.error = message
        self.log(message, Fmi2Status.error)
        return False

    def refuse_step(self) -> bool:
        """doStep's answer after fail(): log the reason again (fmi2Error through the guard)."""
        self.log(f"not stepping: {self.error}", Fmi2Status.error)
        return False


_PYTHONFMU_TYPES = {REAL: Real, INTEGER: Integer, BOOLEAN: Boolean, STRING: String, ENUMERATION: Integer}

__all__ = ["ProjectSlave", "Fmi2Status"]
