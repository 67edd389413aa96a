"""Closed-loop control of the robot: the envelope, references, controllers, tasks, metrics.

    from runtime.control.task import load_task
    from runtime.control.benchmark import run_task
    result, reference, metrics = run_task(load_task("circle").with_controller("nmpc"))

One job per module: `geometry` (what a controller reads off a state: heading, lean, speed),
`reference` (speed, heading and path references), `controller` (the interface: rate, torque
limits, saturation), `pid` (the PID baseline), `lqr_design` (reduced error coordinates, operating
points, linearisation, Riccati), `lqr` (the gain schedule and the C law), `lqr_law` (the C law
written out in NumPy, what its tests check it against), `nmpc` (real-time-iteration NMPC on the
model as CasADi), `firmware` (the closed-loop firmware example's task header), `closed_loop` (the simulation), `task` (task files), `metrics` (the `tracking` numbers),
`plots`, `benchmark` (`make control`), `envelope` (what the torque limits allow), `climbing` (the slope a
torque can climb): docs/control.md.  The linearisations (Floquet exponents of steady rolling) are
runtime/stability.py, in the core.
"""
