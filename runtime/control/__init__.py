"""Closed-loop control of the robot (issue #20): the envelope, references, controllers, tasks, metrics.

    from runtime.control.task import load_task
    from runtime.control.closed_loop import run_task
    result = run_task(load_task("circle"))        # closed loop on the C steppers, zero-order hold

One job per module: `geometry` (what a controller reads off a state: heading, lean, speed),
`reference` (speed, heading and path references), `controller` (the interface: rate, torque
limits, saturation), `pid` (the PID baseline), `closed_loop` (the simulation), `task` (task
files), `metrics` (the `tracking` numbers), `plots`, `benchmark` (`make control`), `envelope`
(what the torque limits allow: docs/control.md).
"""
