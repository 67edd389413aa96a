"""Identification of a robot from its logs (docs/identification.md): the base parameters of
its inertial parameters (`base_parameters`)."""
