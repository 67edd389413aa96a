"""The robot for other tools: `fmu` builds it as an FMI 2.0 and FMI 3.0 co-simulation FMU
(`python -m runtime export fmu`), `mjcf` writes it as a MuJoCo model (`python -m runtime export
mjcf`) and `mujoco_compare` runs a scenario in both MuJoCo and the kernels
(`python -m runtime compare-mujoco`); docs/interop.md."""
