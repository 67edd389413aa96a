"""WHAT is emitted: the declarative list of kernels.

Each kernel is (name, inputs, outputs): inputs are the arrays it reads
(`p` parameters, `c` constants, `x` state, `u` input), outputs are named
arrays of SymPy expressions.  All kernels of a file share nothing at run
time; within a kernel common subexpressions are eliminated by SymPy's CSE.
`rhs` and `accel` evaluate f in the body-by-body form of
`derive.newton_euler`, after proving it equal to `dynamics.rhs`; `accel`
additionally solves M ν̇ = f, joint accelerations first (see
`joint_first.emit_shell_solve`: M is symmetric positive definite, so no
pivoting is needed and no square root is taken).
"""
from .. import contact as CF
from .. import derivatives as J
from .. import dynamics as D
from .. import newton_euler as NE
from .. import param_derivatives as PD
from .. import parameters as P
from .. import robot as R
from .. import sensors as SE
from .. import state as S
from .. import yoke_frame as YF
from .joint_first import joint_first_system
from .spec import Kernel, Output


INPUT_DOCS = {
    "pp": ("const sr_real pp[SR_GEN_NPAPER]", "the paper's parameters (r, m_S, k_S, b, h, m_b, m_h, k_Y, l, m_P, k_P, g), SI"),
    "p": ("const sr_real p[SR_GEN_NPARAM]", "parameters of the general robot (SR_P_*), SI"),
    "c": ("const sr_real c[SR_GEN_NCONST]", "constants from sr_gen_constants"),
    "cg": ("const sr_real cg[SR_GEN_GENERAL_NCONST]", "constants from sr_gen_general_constants"),
    "x": ("const sr_real x[SR_GEN_NX]", "state [R_S | R_Y | R_P | q | w_S | w_Y | w_P]"),
    "u": ("const sr_real u[SR_GEN_NU]", "motor torques (yoke, pendulum) [N m]"),
    "sc": ("const sr_real sc[SR_GEN_NSC]", "sensor constants from sr_gen_sensor_constants (SR_SC_*)"),
    "nud": ("const sr_real nud[SR_GEN_NV]", "accelerations nu_dot = (dw_S, dw_Y, dw_P) [rad/s^2]"),
    "mount": ("const sr_real mount[SR_GEN_NMOUNT]", "sensor mount: lever arm (body frame) [m], then R_m row-major (SR_MOUNT_*)"),
    "bias": ("const sr_real bias[SR_GEN_NBIAS]", "IMU biases: gyroscope [rad/s], accelerometer [m/s^2] (SR_BIAS_*)"),
}


def array_layouts(constants, general_constants):
    """Symbol -> index for each input array; `constants`, `general_constants`: the full constants
    arrays of the paper's and the general kernels (named, then pooled)."""
    return {
        "pp": {s: i for i, s in enumerate(P.PAPER_PARAMETERS)},
        "p": {s: i for i, s in enumerate(P.PARAMETERS)},
        "c": {s: i for i, s in enumerate(constants)},
        "cg": {s: i for i, s in enumerate(general_constants)},
        "x": {**S.STATE_LAYOUT, **SE.STATE_LAYOUT},
        "u": S.INPUT_LAYOUT,
        "sc": {s: i for i, s in enumerate(SE.CONSTANTS)},
        "nud": {s: i for i, s in enumerate(SE.nu_dot)},
        "mount": SE.MOUNT_LAYOUT,
        "bias": SE.BIAS_LAYOUT,
    }


def input_symbols(arrays, layouts):
    """Symbol -> (array, index) for the arrays a kernel reads."""
    return {s: (a, i) for a in arrays for s, i in layouts[a].items()}


def proven(name, residuals):
    if any(r != 0 for r in residuals):
        raise ValueError(f"{name}: the evaluated form differs from the derivation: {residuals}")


def rhs_program():
    """f body by body in the shell frame: (definitions, f), after the proof of `newton_euler`."""
    proven("newton_euler", NE.check_equal_to_rhs())
    p, f = NE.program()
    return tuple(p.definitions), f


def accel_program():
    """(definitions, outputs of joint_first_system) in the yoke frame, at the shell-frame state.

    After the proofs of `newton_euler` and `yoke_frame`.
    """
    proven("newton_euler", NE.check_equal_to_rhs())
    proven("yoke_frame", YF.check_equivalence())
    sub = YF.from_shell_frame()
    p, f = YF.program()
    definitions = tuple((symbol, value.xreplace(sub)) for symbol, value in p.definitions)
    solve_definitions, outputs = joint_first_system(YF.inertia().xreplace(sub), f.xreplace(sub))
    return definitions + solve_definitions, outputs


def kernels():
    """The functions to emit: the paper-geometry kernels (`c`), the conversion of the paper's
    parameters, and the general robot's kernels (`cg`, `general_kernels`)."""
    M = D.inertia()
    rhs_definitions, f = rhs_program()
    accel_definitions, accel_outputs = accel_program()
    return (
        Kernel("constants", "Derived constants of Section 2.3 from the twelve parameters, c[0..11] ="
               " (r, l, g, m_P, m_R, j_S, j_xx, j_yy, j_P, k_S, k_Y, k_P), then the parameter-only"
               " subexpressions of the kernels, computed once per model:",
               ("p",), (Output("c", tuple(P.constant_expressions()), "constants (r, l, g, m_P, m_R, j_S, j_xx, j_yy, j_P, k_S, k_Y, k_P)"),), finite_or_untouched=False),
        Kernel("inertia", "Generalized inertia M(γ, R_Y, R_P), row-major 5x5, kinetic energy ½νᵀMν.",
               ("c", "x"), (Output("M", tuple(M), "M, row-major 5x5"),)),
        Kernel("rhs", "Right-hand side f of M ν̇ = f: gyroscopic, non-holonomic, gravity, motor and friction terms.",
               ("c", "x", "u"), (Output("f", tuple(f), "f"),), definitions=rhs_definitions),
        Kernel("energy", "Total energy: ½νᵀMν + m_P g e_zᵀ(q + R_S R_Y R_P c̄_P) [J].",
               ("c", "x"), (Output("E", (D.energy(),), "energy"),)),
        Kernel("equilibrium_residual", "f at ν = 0, u = 0 (eq. 106); zero iff R_S R_Y R_P e_z = ±e_z (eq. 108).",
               ("c", "x"), (Output("res", tuple(D.equilibrium_residual()), "residual"),)),
        Kernel("accel", "ν̇ = (ω̇_S, ω̇_Y, ω̇_P) solving M ν̇ = f, joints first; SR_GEN_SINGULAR if M is not positive definite.",
               ("c", "x", "u"), accel_outputs, solve=True, definitions=accel_definitions, lanes=True),
        accel_jacobian_yoke_terms(),
        Kernel("paper_params", "The paper's robot (Section 2.3) as a general one: p[SR_P_*] from the"
               " paper's twelve parameters (derive.parameters.from_paper).",
               ("pp",), (Output("p", tuple(P.from_paper()), "parameters of the general robot"),)),
    ) + general_kernels() + sensor_kernels() + contact_kernels()


UPPER = tuple((i, j) for i in range(S.NV) for j in range(i, S.NV))


def general_kernels():
    """The general robot (derive.robot.GENERAL): M of derive.dynamics with CSE, f body
    by body (derive.newton_euler.general_program, proven equal to dynamics.rhs first); the solve of
    M ν̇ = f is hand-written (c/src/sr_kernels.c), since with rotors and general tensors every entry of
    M may be non-zero."""
    robot = R.GENERAL
    M = D.inertia(robot)
    proven("newton_euler (general robot)", NE.check_general_equal_to_rhs())
    program, f = NE.general_program()
    definitions = tuple(program.definitions)
    return (
        Kernel("general_constants", "Constants of the general kernels from the parameters, cg[0..] ="
               f" ({', '.join(s.name for s, _ in R.general_constants())}), then the parameter-only"
               " subexpressions of the kernels:",
               ("p",), (Output("cg", tuple(e for _, e in R.general_constants()), "constants"),), finite_or_untouched=False),
        Kernel("general_inertia", "Generalized inertia M of the general robot, row-major 5x5.",
               ("cg", "x"), (Output("M", tuple(M), "M, row-major 5x5"),)),
        Kernel("general_rhs", "Right-hand side f of M ν̇ = f for the general robot (body by body,"
               " derive.newton_euler.general_program, proven equal to the derivation).",
               ("cg", "x", "u"), (Output("f", tuple(f), "f"),), definitions=definitions),
        Kernel("general_system", "M (upper triangle, row by row) and f of the general robot, for the solve of sr_accel.",
               ("cg", "x", "u"), (Output("M", tuple(M[i, j] for i, j in UPPER), "M, upper triangle row by row"),
                                  Output("f", tuple(f), "f")), definitions=definitions),
        Kernel("general_energy", "Total energy of the general robot: ½νᵀMν + m_R g_x q_x + m_P g_z q_z"
               " + the shape potential [J] (derive.lagrangian.total_energy).",
               ("cg", "x"), (Output("E", (D.energy(robot),), "energy"),)),
        Kernel("general_equilibrium_residual", "f at ν = 0, u = 0 for the general robot.",
               ("cg", "x"), (Output("res", tuple(D.equilibrium_residual(robot)), "residual"),)),
        accel_jacobian_terms(robot, "general_accel_jacobian_terms", ("cg", "x", "u")),
    ) + param_kernels()


def param_kernels():
    """The derivatives in the parameters (derive.param_derivatives): ∂(M ν̇ − f)/∂p for the parameter
    Jacobians of c/src/sr_param_jacobians.c (∂ν̇/∂p = −M⁻¹ ∂(M ν̇ − f)/∂p), and the regressor Y with
    M ν̇ − f(u = 0) = Y π.  Both read the parameters and ν̇ (as an input, held)."""
    proven("regressor", PD.check_regressor())
    proven("inertial parameters", PD.check_inertial_parameters())
    return (
        Kernel("general_param_residual_jacobian", "∂(M ν̇ − f)/∂p of the general robot with ν̇ held (5 x SR_GEN_NPARAM,"
               " row-major, columns SR_P_*), for ∂ν̇/∂p = −M⁻¹ ∂(M ν̇ − f)/∂p (derive.param_derivatives).",
               ("p", "x", "nud"), (Output("dR", tuple(PD.residual_param_jacobian()), "d(M nu_dot - f)/dp, row-major 5 x SR_GEN_NPARAM"),)),
        Kernel("regressor", "The regressor Y (5 x SR_GEN_NPI, row-major, columns SR_PI_*): M ν̇ − f(u = 0) = Y π, π the"
               " inertial parameters and dampings (derive.param_derivatives.INERTIAL_PARAMETERS).",
               ("p", "x", "nud"), (Output("Y", tuple(PD.regressor()), "Y, row-major 5 x SR_GEN_NPI"),), lanes=True),
    )


def accel_jacobian_yoke_terms():
    """What the paper robot's sr_accel_jacobian (c/src/sr_jacobians.c) needs, in the yoke frame
    (derive.derivatives, "the paper's robot in the yoke frame"), at the shell-frame state: one
    kernel, so that CSE shares M', f' and their derivatives."""
    sub = YF.from_shell_frame()
    M, f = YF.inertia(), YF.rhs()
    dM = J.yoke_inertia_derivatives()
    return Kernel(
        "accel_jacobian_yoke_terms",
        "The yoke frame's M' (upper triangle, row by row), f', ∂f'/∂(δξ', δθ_P, δν') (5 x 9, row-major),"
        " ∂f'/∂u (5 x 2) and ∂M'/∂(δξ', δθ_P) (4 upper triangles), at γ' = R_Y^T γ, ν' = diag(R_Y^T, 1, 1) ν,"
        " for the paper robot's accel Jacobian (c/src/sr_jacobians.c: g = M'⁻¹ f', ∂g = M'⁻¹(∂f' − (∂M') g),"
        " and the chain rule to the error coordinates).",
        ("c", "x", "u"),
        (Output("M", tuple(M[i, j].xreplace(sub) for i, j in UPPER), "M', upper triangle row by row"),
         Output("f", tuple(e.xreplace(sub) for e in f), "f'"),
         Output("df", tuple(e.xreplace(sub) for e in J.yoke_rhs_jacobian()), "df'/d(xi', th_P, nu'), row-major 5 x 9"),
         Output("dfdu", tuple(f.jacobian(S.u)), "df'/du, row-major 5 x 2"),
         Output("dM", tuple(m[i, j].xreplace(sub) for m in dM for i, j in UPPER), "dM'/d(xi', th_P)_k, k < 4, upper triangles")))


def accel_jacobian_terms(robot, name, inputs):
    """What the solves of the general robot's sr_accel_jacobian (c/src/sr_jacobians.c) need, in one
    kernel so that CSE shares M, f and their derivatives (derive.derivatives): ∂ν̇ = M⁻¹(∂f − (∂M) ν̇)."""
    upper = UPPER
    M, f = D.inertia(robot), D.rhs(robot)
    dM = J.inertia_derivatives(robot)
    return Kernel(
        name,
        "M (upper triangle, row by row), f, ∂f/∂d (5 x SR_GEN_NE, row-major, error coordinates of"
        " SR_E_*), ∂f/∂u (5 x 2) and ∂M/∂d along δξ_S, δθ_Y, δθ_P (5 upper triangles) for the"
        " accel Jacobian ∂ν̇ = M⁻¹(∂f − (∂M) ν̇).",
        inputs,
        (Output("M", tuple(M[i, j] for i, j in upper), "M, upper triangle row by row"),
         Output("f", tuple(f), "f"),
         Output("df", tuple(J.rhs_jacobian(robot)), "df/dd, row-major 5 x SR_GEN_NE"),
         Output("dfdu", tuple(J.rhs_input_jacobian(robot)), "df/du, row-major 5 x 2"),
         Output("dM", tuple(m[i, j] for m in dM for i, j in upper), "dM/dd_k, k < 5, upper triangles")),
        lanes=True)


def sensor_kernels():
    """The sensor models of derive.sensors, per body (the mount's lever arm and rotation are run-time
    inputs): the IMU's reading and its Jacobians, the heading vector and the heading's Jacobian, and
    the constant Jacobians of the encoders and the position fix.  The biases, the rows of R_S and
    the joint angles read by atan2 are checked and formed in c/src/sr_sensors.c."""
    ks = [Kernel("sensor_constants", "The sensor kernels' constants sc = (r, g sin(slope), g cos(slope)) (SR_SC_*)"
                 " from the parameters (derive.sensors.constant_expressions).",
                 ("p",), (Output("sc", SE.constant_expressions(), "(r, g_x, g_z)"),))]
    imu_inputs = ("sc", "x", "nud", "mount", "bias")
    for body in SE.BODIES:
        y = SE.imu(body)
        H, Hn = SE.imu_jacobians(body)
        ks.append(Kernel(
            f"imu_{body}", f"IMU on the {body}: y = (gyroscope R_m^T w_B + b_g, accelerometer R_m^T R_B^T (p'' - g) + b_a)"
            " in the sensor frame (SR_IMU_*), at the mount's lever arm, given nu_dot (derive.sensors.imu).",
            imu_inputs, (Output("y", tuple(y), "y (SR_IMU_*)"),)))
        ks.append(Kernel(
            f"imu_{body}_jacobian", f"IMU on the {body}: y, dy/d(d, b) with nu_dot held (SR_GEN_NIMU x SR_GEN_NEB, row-major,"
            " columns SR_EB_*) and dy/d(nu_dot) (SR_GEN_NIMU x SR_GEN_NV), so that dy/dd = H + Hn Ja (derive.sensors.imu_jacobians).",
            imu_inputs, (Output("y", tuple(y), "y (SR_IMU_*)"),
                         Output("H", tuple(H), "dy/d(d, b), nu_dot held, row-major 6 x SR_GEN_NEB"),
                         Output("Hn", tuple(Hn), "dy/d(nu_dot), row-major 6 x SR_GEN_NV"))))
        ks.append(Kernel(
            f"heading_{body}", f"Heading sensor on the {body}: h = (h_x, h_y), the sensor's x axis R_B R_m e_x on the floor's"
            " axes; the heading is atan2(h_y, h_x) (derive.sensors.heading_vector).",
            ("x", "mount"), (Output("h", tuple(SE.heading_vector(body)), "(h_x, h_y)"),)))
        ks.append(Kernel(
            f"heading_{body}_jacobian", f"Heading sensor on the {body}: h as sr_gen_heading_{body} and the heading's"
            " d(atan2(h_y, h_x))/d(d, b) (1 x SR_GEN_NEB; not finite where h = 0) (derive.sensors.heading_jacobian).",
            ("x", "mount"), (Output("h", tuple(SE.heading_vector(body)), "(h_x, h_y)"),
                             Output("H", tuple(SE.heading_jacobian(body)), "d heading/d(d, b)"))))
    ks.append(Kernel("encoders_jacobian", "Joint encoders (theta_Y, theta_P): d/d(d, b), 2 x SR_GEN_NEB row-major"
                     " (derive.sensors.encoders_jacobian).",
                     (), (Output("H", tuple(SE.encoders_jacobian()), "d(theta_Y, theta_P)/d(d, b)"),), finite_or_untouched=False))
    ks.append(Kernel("position_jacobian", "Position fix (q_x, q_y): d/d(d, b), 2 x SR_GEN_NEB row-major"
                     " (derive.sensors.position_jacobian).",
                     (), (Output("H", tuple(SE.position_jacobian()), "d(q_x, q_y)/d(d, b)"),), finite_or_untouched=False))
    return tuple(ks)


def contact_kernels():
    """The floor's force on the shell (derive.contact), for the paper's robot (`c`) and the general
    one (`cg`), given ν̇ from the accel kernel (c/src/sr_kernels.c: sr_contact_force)."""
    doc = ("Contact force F = (F_x, F_y, F_z) of the floor on the shell, plane frame (z the floor's normal) [N],"
           " from the total momentum balance F = sum m_B p''_B - m_R g at the accelerations nud (derive.contact).")
    return (
        Kernel("contact_force", doc, ("c", "x", "nud"),
               (Output("F", tuple(CF.contact_force(R.PAPER)), "contact force, plane frame [N]"),)),
        Kernel("general_contact_force", doc.replace("Contact force", "General robot: contact force"), ("cg", "x", "nud"),
               (Output("F", tuple(CF.contact_force(R.GENERAL)), "contact force, plane frame [N]"),)),
    )
