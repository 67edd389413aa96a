"""The robot for other tools: `fmu` builds it as an FMI 2.0 and FMI 3.0 co-simulation FMU
(`python -m runtime export fmu`, docs/interop.md)."""
