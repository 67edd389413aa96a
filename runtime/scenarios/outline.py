"""What the figures and the replay draw of a robot: the yoke's outline and the pendulum's rod.

The paper's robot (Params.paper) is drawn as built: the h × b rectangle of rods and the rod of
length l.  A general robot has no shapes, only masses, centres and tensors: its yoke is drawn as
the rectangle, centred on c_Y in the yoke's x-y plane, of a uniform plate with the yoke's mass and
its moments about x and y, and its pendulum as a rod from the hinge through its centre of mass
to twice that distance (a uniform rod's tip).
"""
import numpy as np


def yoke_outline(params):
    """Closed polyline (5 × 3) of the yoke in its own frame."""
    if params.paper_params is not None:
        half = np.array([params.paper_params.h / 2, params.paper_params.b / 2])
        centre = np.zeros(3)
    else:
        J = np.asarray(params.J_Y)
        half = np.sqrt(3 * np.array([J[1, 1], J[0, 0]]) / params.m_Y)
        centre = np.asarray(params.c_Y)
    corners = [(1, 1), (-1, 1), (-1, -1), (1, -1), (1, 1)]
    return np.array([centre + [sx * half[0], sy * half[1], 0.0] for sx, sy in corners])


def rod_tip(params):
    """The pendulum rod's far end in the pendulum frame (−l e_z for the paper's robot)."""
    if params.paper_params is not None:
        return np.array([0.0, 0.0, -params.paper_params.l])
    return 2 * np.asarray(params.c_P)
