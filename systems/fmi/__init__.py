"""FMI around the FMUs: building them, SSP packages of the diagram, co-simulation masters
(fmpy, libcosim) and `attitude verify`."""
