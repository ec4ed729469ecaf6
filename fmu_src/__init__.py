"""Sources of the project's FMUs: thin pythonfmu adapters over blocks/ and systems/ (AttitudeEstimator.py, …),
and the C of the native ones: the FMI 2.0 and 3.0 plumbing (fmi2/, fmi3/), each model file (models/), the exported
diagrams' runtime (diagram/) and the pythonfmu FMUs' guard binary (fmi2_guard.c). Their variable tables and the
model descriptions written from them are systems.fmi.interface's, below this package: nothing in systems/ imports
from here."""
