"""The model-specific joint-first solve of M ν̇ = f: the symbolic system and its C emission."""
import sympy as sp

from .spec import Output


def upper_triangle(M):
    return tuple(M[i, j] for i in range(M.rows) for j in range(i, M.cols))


def joint_first_system(M, f):
    """M ν̇ = f with the joint accelerations eliminated: (definitions, outputs) of the `accel` kernel.

    M = [A B; Bᵀ D] with A the 3×3 shell block and D = diag(M_33, M_44): the
    yoke and pendulum rates do not couple (M_34 = 0 identically, asserted
    here).  The shell accelerations solve S ω̇_S = g with the Schur complement
    S = A − β Bᵀ, g = f_S − β f_J, β = B D⁻¹ (1/M_44 = 1/j_P is a per-model
    constant, and 1/M_33 is ready early, off the critical path); then
    ω̇_J = D⁻¹ f_J − βᵀ ω̇_S.  The entries of β are definitions (named
    `beta_i_k`; those of zero entries of B are left out), so that each term
    of β Bᵀ costs one multiplication, not the two of B_ik B_jk / d_k.  All of
    it is symbolic, so CSE and the constant pool see it together with M and f.
    """
    if sp.simplify(M[3, 4]) != 0:
        raise ValueError("joint-first solve needs M_34 = 0: the yoke and pendulum rates couple")
    A, B, d = M[0:3, 0:3], M[0:3, 3:5], (M[3, 3], M[4, 4])
    definitions, beta = [], sp.zeros(3, 2)
    for i in range(3):
        for k in range(2):
            if sp.expand(B[i, k]) != 0:
                beta[i, k] = sp.Symbol(f"beta_{i}_{k + 3}", real=True)
                definitions.append((beta[i, k], B[i, k] / d[k]))
    S_ = A - beta * B.T
    g_ = f[0:3, 0] - beta * f[3:5, 0]
    return tuple(definitions), (
        Output("S", upper_triangle(S_), "Schur complement, upper triangle", ("S_0_0", "S_0_1", "S_0_2", "S_1_1", "S_1_2", "S_2_2")),
        Output("g", tuple(g_), "reduced right-hand side", ("g_0", "g_1", "g_2")),
        Output("fD", (f[3] / d[0], f[4] / d[1]), "D^-1 f_J", ("fD_3", "fD_4")),
        Output("D", d, "joint inertias", ("M_3_3", "M_4_4")),
        Output("Mdiag", (M[0, 0], M[1, 1], M[2, 2]), "diagonal of A, the scale of the pivot tests", ("M_0_0", "M_1_1", "M_2_2")),
    )


def emit_shell_solve(scheduler, out_name, rotation, defined, guard):
    """C for the rest of `joint_first_system`: S ω̇' = g by the adjugate of S, then the joints.

    M is positive definite iff M_33, M_44 and the leading minors of S are
    positive; as in an LDLᵀ, each pivot must exceed SR_GEN_PIVOT_TOL times
    M's diagonal entry.  1/M_33 is formed before its test: a zero or
    negative M_33 gives an infinity or a wrong sign that is never used.  The
    shell accelerations come out in the frame of the system (the yoke frame,
    see `derive.yoke_frame`) and are written as `rotation` times them.
    Couplings β_ik not among the `defined` names are identically zero and left out.
    `guard(condition, status)` is the C line of a test that must hold (`emit.Guards`).
    """
    def sym(name):
        return sp.Symbol(name, real=True)

    S_ = sp.Matrix(3, 3, lambda i, j: sym(f"S_{min(i, j)}_{max(i, j)}"))
    C_ = S_.adjugate()
    C = sp.Matrix(3, 3, lambda i, j: sym(f"C_{min(i, j)}_{max(i, j)}"))
    g, a = sp.Matrix([sym(f"g_{i}") for i in range(3)]), [sym(f"a_{i}") for i in range(5)]
    beta = sp.Matrix(3, 2, lambda i, k: sym(f"beta_{i}_{k + 3}") if f"beta_{i}_{k + 3}" in defined else 0)

    def let(name, value):
        return f"    const sr_real {name} = {scheduler.assign(name, value)};"

    lines = ["    /* M positive definite: the joint block, then the leading minors of S; C = adj S (symmetric). */",
             guard("M_3_3 > 0", "SR_GEN_SINGULAR"), guard("M_4_4 > 0", "SR_GEN_SINGULAR")]
    lines += [let(f"C_{i}_{j}", C_[i, j]) for i in range(3) for j in range(i, 3)]
    lines += [
        let("det_S", (S_.row(0) * C.col(0))[0]),
        guard("S_0_0 > SR_GEN_PIVOT_TOL*M_0_0", "SR_GEN_SINGULAR"),
        guard("C_2_2 > SR_GEN_PIVOT_TOL*M_1_1*S_0_0", "SR_GEN_SINGULAR"),
        guard("det_S > SR_GEN_PIVOT_TOL*M_2_2*C_2_2", "SR_GEN_SINGULAR"),
        let("inv_det_S", 1 / sym("det_S")),
    ]
    lines += [let(f"a_{i}", (C.row(i) * g)[0] * sym("inv_det_S")) for i in range(3)]
    lines += [let(f"a_{k + 3}", sym(f"fD_{k + 3}") - (beta.col(k).T * sp.Matrix(a[0:3]))[0]) for k in range(2)]
    shell_out = rotation * sp.Matrix(a[0:3])
    return lines, [(f"{out_name}[{i}]", value) for i, value in enumerate(list(shell_out) + a[3:5])]
