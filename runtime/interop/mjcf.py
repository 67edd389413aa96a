"""The robot as a MuJoCo model (MJCF), generated from `runtime.Params`.

`python -m runtime export mjcf [--params ROBOT.toml] [--u-max U] --out FILE.xml` writes it.
The bodies, in MuJoCo's terms (docs/interop.md, "MuJoCo"):

* `shell`: a sphere of radius r, mass m_S and isotropic inertia j_S about its centre, free to move
  through three slide joints and a ball joint (together a free joint; split so that the shell's
  damping k_S acts on its rotation alone: MuJoCo damps a ball joint's angular velocity, −k_S ω_S,
  where a free joint's one damping would also brake the translation).
* `yoke`: a child of the shell at its centre, hinged about the shell's x axis; mass m_Y, centre
  c_Y, full inertia tensor J_Y about c_Y; joint damping k_Y.
* `pendulum`: a child of the yoke at the same point, hinged about the yoke's y axis; m_P, c_P, J_P,
  damping k_P.
* the motors: torque actuators on the two hinges, `gear` n_Y, n_P, so that `ctrl` is the rotor's
  torque and the joint torque u = n·ctrl; `ctrlrange` ±u_max/|n|.  A rotor's axial inertia j_m
  is MuJoCo's reflected inertia n² j_m (`armature`) plus j_m on its carrier's axis (the shell's x
  for the yoke motor, the yoke's y for the pendulum motor); the model's cross term
  j_m n ω_carrier ω_joint, of relative size 1/n, has no MuJoCo counterpart and is left out.
* the floor: the plane z = 0 of the inertial frame, which lies in the slope with x up it, so the
  slope tilts gravity: (−g sin(slope), 0, −g cos(slope)), as in the model.

Contact (the shell's sphere on the plane): `condim` 3, the contact point's velocity constrained
and nothing else, as in the model's rolling without slipping (the shell spins about the normal and
rolls without resistance: condim 4 or 6 would add torsional and rolling friction the model does not
have); elliptic friction cones, a friction coefficient far above what the runs need, `impratio`
making friction as stiff as the normal direction, no-slip iterations that remove the soft
contact's creep, and a tight `solref`/`solimp` (`ContactSettings`, `EXPORTED`), all on an explicit
contact pair of the shell and the floor (the shell's geom collides through it alone).
"""
import argparse
import dataclasses
import math
import sys
import xml.etree.ElementTree as ET

import numpy as np

from runtime.atomic import output_file, write_text
from runtime.params import Params
from runtime.scenario import load_robot

DEFAULT_U_MAX = 0.5
"""The motors' torque limit at the joints [N m] when none is given: the control benchmark's u_max."""


@dataclasses.dataclass(frozen=True)
class ContactSettings:
    """MuJoCo's numerics for the shell's contact and the time step (the `<option>` and the contact
    pair's `condim`, `friction`, `solref`, `solimp`)."""
    timestep: float = 1e-3              # [s]
    integrator: str = "RK4"             # the motion is smooth (a rolling contact): fourth order pays
    cone: str = "elliptic"
    condim: int = 3
    friction: float = 10.0              # sliding friction coefficient μ (far above what the runs need)
    impratio: float = 100.0             # friction impedance over normal: friction as hard as the contact
    noslip_iterations: int = 20         # MuJoCo's no-slip post-solver: removes creep under tangential load
    noslip_tolerance: float = 1e-10
    iterations: int = 100
    tolerance: float = 1e-12
    solref: tuple = (0.002, 1.0)        # time constant [s], damping ratio: critically damped, 2 timesteps
    solimp: tuple = (0.99, 0.9999, 1e-4, 0.5, 2.0)   # impedance: hard from 0 to 0.1 mm of penetration

    def replace(self, **changes):
        """A copy with some settings changed."""
        return dataclasses.replace(self, **changes)

    def as_json(self):
        """The settings as a dict (for summaries)."""
        return {f.name: (list(v) if isinstance(v, tuple) else v)
                for f, v in ((f, getattr(self, f.name)) for f in dataclasses.fields(self))}


EXPORTED = ContactSettings()
"""The contact settings written into an exported model."""


def _num(value):
    """A float as MJCF text, exact (repr round-trips)."""
    return repr(float(value))


def _nums(values):
    return " ".join(_num(v) for v in values)


MIN_PRINCIPAL = 1e-9
"""The least principal moment written, relative to the largest: MuJoCo refuses a zero one (the
paper's pendulum is a slender rod, J_zz = 0), so a smaller one is raised to this; its effect on the
motion is of this relative size."""


def _fullinertia(J):
    """J in MJCF's fullinertia order (Ixx Iyy Izz Ixy Ixz Iyz), principal moments below
    MIN_PRINCIPAL of the largest raised to it."""
    moments, axes = np.linalg.eigh(np.asarray(J, dtype=float))
    floor = MIN_PRINCIPAL * moments.max()
    if moments.min() < floor:
        J = axes @ np.diag(np.maximum(moments, floor)) @ axes.T
    J = np.asarray(J, dtype=float)
    return _nums([J[0, 0], J[1, 1], J[2, 2], J[0, 1], J[0, 2], J[1, 2]])


def to_mjcf(params=None, u_max=DEFAULT_U_MAX, contact=EXPORTED):
    """The MJCF text (str) of the robot `params` (default: `Params.paper_simulation()`), with motor
    limits ±u_max at the joints [N m] and the contact numerics `contact`."""
    params = Params.paper_simulation() if params is None else params
    if not isinstance(params, Params):
        raise ValueError(f"mjcf: params: expected a runtime.Params, got {type(params).__name__}")
    if not (isinstance(u_max, (int, float)) and math.isfinite(u_max) and u_max > 0):
        raise ValueError(f"mjcf: u_max: must be a finite torque > 0 N m, got {u_max!r}")
    p = params
    root = ET.Element("mujoco", model="spherical_robot")
    ET.SubElement(root, "compiler", angle="radian", inertiafromgeom="false", autolimits="true")
    option = ET.SubElement(root, "option", timestep=_num(contact.timestep), integrator=contact.integrator,
                           cone=contact.cone, impratio=_num(contact.impratio),
                           iterations=str(contact.iterations), tolerance=_num(contact.tolerance),
                           noslip_iterations=str(contact.noslip_iterations),
                           noslip_tolerance=_num(contact.noslip_tolerance),
                           gravity=_nums([-p.g * math.sin(p.slope), 0.0, -p.g * math.cos(p.slope)]))
    ET.SubElement(option, "flag", energy="enable")
    world = ET.SubElement(root, "worldbody")
    ET.SubElement(world, "geom", name="floor", type="plane", size="0 0 1", contype="0", conaffinity="0",
                  rgba="0.8 0.8 0.8 1")
    shell = ET.SubElement(world, "body", name="shell", pos=_nums([0.0, 0.0, p.r]))
    for axis, vector in zip("xyz", ("1 0 0", "0 1 0", "0 0 1")):
        ET.SubElement(shell, "joint", name=f"shell_{axis}", type="slide", axis=vector)
    ET.SubElement(shell, "joint", name="shell_rotation", type="ball", damping=_num(p.k_S))
    # The yoke motor's rotor turns about the shell's x axis with the shell: j_mY on that axis.
    ET.SubElement(shell, "inertial", pos="0 0 0", mass=_num(p.m_S),
                  fullinertia=_nums([p.j_S + p.j_mY, p.j_S, p.j_S, 0.0, 0.0, 0.0]))
    # Collisions only through the explicit pair below: a geom-generated contact would mix the floor's
    # default solref/solimp into the shell's (solmix) and soften it.
    ET.SubElement(shell, "geom", name="shell", type="sphere", size=_num(p.r), contype="0", conaffinity="0",
                  rgba="0.3 0.5 0.9 0.3")
    yoke = ET.SubElement(shell, "body", name="yoke", pos="0 0 0")
    ET.SubElement(yoke, "joint", name="yoke", type="hinge", axis="1 0 0", damping=_num(p.k_Y),
                  armature=_num(p.j_mY * p.n_Y ** 2))
    J_Y = np.array(p.J_Y) + np.diag([0.0, p.j_mP, 0.0])    # the pendulum motor's rotor, on the yoke's y
    ET.SubElement(yoke, "inertial", pos=_nums(p.c_Y), mass=_num(p.m_Y), fullinertia=_fullinertia(J_Y))
    pendulum = ET.SubElement(yoke, "body", name="pendulum", pos="0 0 0")
    ET.SubElement(pendulum, "joint", name="pendulum", type="hinge", axis="0 1 0", damping=_num(p.k_P),
                  armature=_num(p.j_mP * p.n_P ** 2))
    ET.SubElement(pendulum, "inertial", pos=_nums(p.c_P), mass=_num(p.m_P), fullinertia=_fullinertia(p.J_P))
    contacts = ET.SubElement(root, "contact")
    ET.SubElement(contacts, "pair", name="shell_floor", geom1="floor", geom2="shell", condim=str(contact.condim),
                  friction=_nums([contact.friction, contact.friction, 0.0, 0.0, 0.0]),
                  solref=_nums(contact.solref), solimp=_nums(contact.solimp))
    actuators = ET.SubElement(root, "actuator")
    for joint, n in (("yoke", p.n_Y), ("pendulum", p.n_P)):
        limit = u_max / abs(n)
        ET.SubElement(actuators, "motor", name=f"{joint}_motor", joint=joint, gear=_num(n),
                      ctrlrange=_nums([-limit, limit]))
    ET.indent(root)
    comment = ("<!-- The yoke-pendulum spherical robot, generated by python -m runtime export mjcf from "
               "runtime.Params (docs/interop.md). ctrl is the rotor torque: joint torque = gear * ctrl. -->\n")
    return comment + ET.tostring(root, encoding="unicode") + "\n"


def export(path, params=None, u_max=DEFAULT_U_MAX, contact=EXPORTED):
    """Write the MJCF of `params` to `path` (atomically); returns the path."""
    write_text(path, to_mjcf(params, u_max, contact))
    return path


def main(argv):
    """`python -m runtime export mjcf`: write the robot's MJCF to --out."""
    parser = argparse.ArgumentParser(prog="python -m runtime export mjcf",
                                     description="Write the robot as a MuJoCo model (MJCF).")
    parser.add_argument("--params", default=None,
                        help="a robot file (TOML of general parameters, docs/robots.md); "
                             "default: the paper's robot as Section 5.3 runs it")
    parser.add_argument("--u-max", type=_positive, default=DEFAULT_U_MAX,
                        help=f"the motors' torque limit at the joints, N m (default {DEFAULT_U_MAX})")
    parser.add_argument("--out", required=True, type=output_file, help="the MJCF file to write")
    args = parser.parse_args(argv)
    try:
        params = None if args.params is None else load_robot(args.params)
        print(export(args.out, params, args.u_max))
    except (ValueError, OSError) as exc:
        print(f"export mjcf: {exc}", file=sys.stderr)
        return 1
    return 0


def _positive(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return value
