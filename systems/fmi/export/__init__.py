"""Export of python-control systems as FMUs (export_fmu)."""
