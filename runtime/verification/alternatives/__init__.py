"""Alternative implementations of the same robot, for the benchmark."""
