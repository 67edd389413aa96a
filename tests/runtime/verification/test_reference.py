"""Self-checks of the independent CasADi reference model (runtime/verification/reference.py).

Importing it loads neither the compiled kernels nor derive/ (checked in
tests/runtime/test_imports.py), so these tests do not depend on them.  Checks:

* the chart identities (phidot = omega_S, phiddot = d omega_S/dt at phi = 0);
* static equilibrium, symmetric positive-definite constrained inertia;
* rolling-contact kinematics;
* power balance dE/dt = u.omega - damping, and energy conservation over an
  integrated trajectory without damping or torque;
* agreement with two independent derivations written here in plain numpy:
  Kane's equations with nonholonomic partial velocities (full 3-D), and a
  hand-derived planar rolling-pendulum model (analytic).
"""
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm

from runtime.verification import reference as ref

PAPER = dict(r=0.3, m_S=2.0, k_S=0.08, b=0.2, h=0.5, m_b=2.0, m_h=5.0,
             k_Y=0.02, l=0.2, m_P=1.0, k_P=0.05, g=9.81)


def _random_params(seed):
    rng = np.random.default_rng(seed)
    r = rng.uniform(0.1, 1.0)
    return dict(r=r, m_S=rng.uniform(0.2, 5), k_S=rng.uniform(0, 0.3),
                b=rng.uniform(0.2, 1.6) * r, h=rng.uniform(0.2, 1.6) * r,
                m_b=rng.uniform(0.1, 4), m_h=rng.uniform(0.1, 4), k_Y=rng.uniform(0, 0.3),
                l=rng.uniform(0.1, 0.95) * r, m_P=rng.uniform(0.1, 4), k_P=rng.uniform(0, 0.3),
                g=rng.uniform(1, 20))


PARAM_SETS = {"paper": PAPER, "random1": _random_params(1), "random2": _random_params(2)}


@pytest.fixture(scope="module", params=list(PARAM_SETS))
def model(request):
    return ref.ReferenceModel(PARAM_SETS[request.param])


# ------------------------------------------------------------------ helpers
def _hat(a):
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def _rx(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _ry(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _random_rotation(rng):
    Q, R = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q @ np.diag(np.sign(np.diag(R)))
    return Q * np.sign(np.linalg.det(Q))


def _random_state(rng, r, speed=10.0):
    return ref.make_state(R_S=_random_rotation(rng), theta_Y=rng.uniform(-np.pi, np.pi),
                          theta_P=rng.uniform(-np.pi, np.pi), q_xy=rng.normal(size=2),
                          omega_S=rng.uniform(-speed, speed, 3), omega_Y=rng.uniform(-speed, speed),
                          omega_P=rng.uniform(-speed, speed), r=r)


def _unpack(x):
    return (x[0:9].reshape(3, 3), x[9:18].reshape(3, 3), x[18:27].reshape(3, 3),
            x[27:30], x[30:33], x[33], x[34])


def _advance(x, xdot_nu, qdot, h):
    """Point at time h on a curve through x with the exact kinematic tangent.

    Any such curve has the same first derivative as the true motion, which is
    all a finite-difference estimate of d/dt at h = 0 needs.
    """
    RS, RY, RP, q, wS, wY, wP = _unpack(x)
    return np.concatenate([(RS @ expm(h * _hat(wS))).ravel(), (RY @ _rx(h * wY)).ravel(),
                           (RP @ _ry(h * wP)).ravel(), q + h * qdot, x[30:35] + h * xdot_nu])


def _ddt(f, x, xdot_nu, qdot, h=1e-4):
    """Fourth-order (five-point) central difference of f along the motion at x."""
    c = {1: 8.0, 2: -1.0}
    out = 0.0
    for k, w in c.items():
        out = out + w * (f(_advance(x, xdot_nu, qdot, k * h)) - f(_advance(x, xdot_nu, qdot, -k * h)))
    return out / (12.0 * h)


# Independent rigid-body kinematics in numpy (used by the Kane check).
def _bodies(p):
    ex, ey, ez = np.eye(3)

    def rod(m, L, axis, c, frame):
        return (m, m * L**2 / 12 * (np.eye(3) - np.outer(axis, axis)), c, frame)

    return [(p["m_S"], 2 / 3 * p["m_S"] * p["r"] ** 2 * np.eye(3), np.zeros(3), "S"),
            rod(p["m_b"], p["b"], ey, p["h"] / 2 * ex, "Y"), rod(p["m_b"], p["b"], ey, -p["h"] / 2 * ex, "Y"),
            rod(p["m_h"], p["h"], ex, p["b"] / 2 * ey, "Y"), rod(p["m_h"], p["h"], ex, -p["b"] / 2 * ey, "Y"),
            rod(p["m_P"], p["l"], ez, -p["l"] / 2 * ez, "P")]


def _body_velocities(p, x, nu=None):
    """Per body: (cm inertial velocity, body-frame angular velocity)."""
    RS, RY, RP, q, wS, wY, wP = _unpack(x)
    if nu is not None:
        wS, wY, wP = nu[0:3], nu[3], nu[4]
    ex, ey, ez = np.eye(3)
    qdot = p["r"] * np.cross(RS @ wS, ez)
    wYb = RY.T @ wS + wY * ex
    wPb = RP.T @ wYb + wP * ey
    out = []
    for m, I, c, frame in _bodies(p):
        if frame == "S":
            rho, rhodot, w = np.zeros(3), np.zeros(3), wS
        elif frame == "Y":
            rho, rhodot, w = RY @ c, RY @ np.cross(wY * ex, c), wYb
        else:
            rho = RY @ RP @ c
            rhodot = RY @ np.cross(wY * ex, RP @ c) + RY @ RP @ np.cross(wP * ey, c)
            w = wPb
        out.append((qdot + RS @ (np.cross(wS, rho) + rhodot), w))
    return out


def _kane_accel(p, x, u):
    """Kane's equations: sum_b J_v^T m a + J_w^T (I alpha + w x I w) = F."""
    RS, RY, RP, q, wS, wY, wP = _unpack(x)
    nu = x[30:35]
    bodies = _bodies(p)
    vel = _body_velocities(p, x)
    partial = [_body_velocities(p, x, e) for e in np.eye(5)]     # linear in nu
    qdot = p["r"] * np.cross(RS @ wS, np.eye(3)[2])
    # accelerations with nu_dot = 0 (velocity-dependent part)
    acc0 = _ddt(lambda y: np.concatenate([np.concatenate(vw) for vw in _body_velocities(p, y)]),
                x, np.zeros(5), qdot)
    lhs = np.zeros((5, 5))
    rhs = np.concatenate([-p["k_S"] * wS, [u[0] - p["k_Y"] * wY, u[1] - p["k_P"] * wP]])
    for i, (m, I, c, frame) in enumerate(bodies):
        Jv = np.column_stack([partial[k][i][0] for k in range(5)])
        Jw = np.column_stack([partial[k][i][1] for k in range(5)])
        a0, al0 = acc0[6 * i:6 * i + 3], acc0[6 * i + 3:6 * i + 6]
        w = vel[i][1]
        lhs += m * Jv.T @ Jv + Jw.T @ I @ Jw
        rhs += Jv.T @ (-m * p["g"] * np.eye(3)[2]) - m * Jv.T @ a0 - Jw.T @ (I @ al0 + np.cross(w, I @ w))
    return np.linalg.solve(lhs, rhs), lhs


# -------------------------------------------------------------------- tests
def test_exponential_chart_rates_equal_body_rates_at_base_point(model, rng):
    for _ in range(5):
        J, bias = model.chart_check(_random_state(rng, model.params["r"]))
        np.testing.assert_allclose(J, np.hstack([np.eye(3), np.zeros((3, 4))]), atol=1e-12)
        np.testing.assert_allclose(bias, 0.0, atol=1e-10)


def test_equilibrium_has_zero_acceleration(model):
    x = ref.make_state(r=model.params["r"])
    np.testing.assert_allclose(model.accel(x, [0.0, 0.0]), 0.0, atol=1e-13)


def test_inertia_is_symmetric_positive_definite(model, rng):
    for _ in range(20):
        M = model.inertia(_random_state(rng, model.params["r"]))
        assert M.shape == (5, 5)
        np.testing.assert_allclose(M, M.T, atol=1e-13 * np.abs(M).max())
        assert np.linalg.eigvalsh(M).min() > 0.0


def test_inertia_reproduces_kinetic_energy(model, rng):
    p = model.paper
    for _ in range(10):
        x = _random_state(rng, p["r"])
        nu = x[30:35]
        kin = 0.5 * nu @ model.inertia(x) @ nu
        x_static = x.copy()
        x_static[30:35] = 0.0
        pot = model.energy(x_static)
        np.testing.assert_allclose(model.energy(x) - pot, kin, rtol=1e-12)
        # independent numpy kinematics
        kin_np = sum(0.5 * m * v @ v + 0.5 * w @ I @ w
                     for (m, I, _, _), (v, w) in zip(_bodies(p), _body_velocities(p, x)))
        np.testing.assert_allclose(kin, kin_np, rtol=1e-12)


def test_contact_point_is_at_rest_under_rolling_velocity(model, rng):
    r = model.params["r"]
    for _ in range(20):
        x = _random_state(rng, r)
        v = model.contact_point_velocity(x)
        assert np.abs(v).max() < 1e-12 * max(1.0, r * np.abs(x[30:33]).max())
        # and the centre velocity is r (R_S omega_S) x e_z
        RS = x[0:9].reshape(3, 3)
        np.testing.assert_allclose(model.centre_velocity(x), r * np.cross(RS @ x[30:33], [0, 0, 1]),
                                   atol=1e-12)
        # a slipping centre velocity shows up one-for-one at the contact point
        slip = np.array([0.3, -0.2, 0.0])
        np.testing.assert_allclose(model.contact_point_velocity(x, model.centre_velocity(x) + slip),
                                   slip, atol=1e-12)


def test_power_balance_matches_input_minus_dissipation(model, rng):
    p = model.paper
    worst = 0.0
    for _ in range(10):
        x = _random_state(rng, p["r"])
        u = rng.uniform(-2, 2, 2)
        nu_dot = model.accel(x, u)
        dE = _ddt(model.energy, x, nu_dot, model.centre_velocity(x))
        wS, wY, wP = x[30:33], x[33], x[34]
        power = u[0] * wY + u[1] * wP - p["k_S"] * wS @ wS - p["k_Y"] * wY**2 - p["k_P"] * wP**2
        # scale: magnitude of the kinetic-energy rate terms
        scale = np.abs(nu_dot * (model.inertia(x) @ x[30:35])).sum() + abs(power) + 1.0
        worst = max(worst, abs(dE - power) / scale)
    assert worst < 1e-7, worst


def test_energy_is_conserved_without_damping_or_torque():
    for name in ("paper", "random1"):
        p = dict(PARAM_SETS[name], k_S=0.0, k_Y=0.0, k_P=0.0)
        model = ref.ReferenceModel(p)
        x0 = ref.make_state(R_S=_rx(0.3) @ _ry(-0.2), theta_Y=0.7, theta_P=1.1,
                            omega_S=(1.0, -2.0, 0.5), omega_Y=2.0, omega_P=-1.5, r=p["r"])
        sol = solve_ivp(lambda t, y: model.state_derivative(y, (0.0, 0.0)), (0.0, 3.0), x0,
                        method="DOP853", rtol=1e-11, atol=1e-12, dense_output=False)
        assert sol.success
        E = np.array([model.energy(y) for y in sol.y.T])
        kin_scale = abs(E[0] - model.energy(np.r_[x0[:30], np.zeros(5)])) + 1.0
        assert np.abs(E - E[0]).max() / kin_scale < 1e-8


def test_accel_matches_kane_equations_in_3d(model, rng):
    p = model.paper
    for _ in range(8):
        x = _random_state(rng, p["r"], speed=5.0)
        u = rng.uniform(-2, 2, 2)
        kane, M_kane = _kane_accel(p, x, u)
        np.testing.assert_allclose(model.inertia(x), M_kane, rtol=1e-12, atol=1e-14)
        acc = model.accel(x, u)
        assert np.abs(acc - kane).max() <= 1e-7 * (1.0 + np.abs(kane).max())


def test_accel_matches_planar_rolling_pendulum(model, rng):
    """omega_S = (0, w, 0), theta_Y = 0, omega_Y = 0, u_Y = 0: motion in the x-z plane.

    Coordinates: shell angle alpha about y (x = r alpha), absolute pendulum
    angle psi = alpha + theta_P.  Hand-derived Lagrangian equations.
    """
    p = model.paper
    r, l, mP, g = p["r"], p["l"], p["m_P"], p["g"]
    mY = 2 * (p["m_b"] + p["m_h"])
    JS = 2 / 3 * p["m_S"] * r**2
    JYy = (p["m_b"] / 2 + p["m_h"] / 6) * p["h"] ** 2
    for _ in range(10):
        alpha, thP = rng.uniform(-np.pi, np.pi, 2)
        ad, thPd = rng.uniform(-5, 5, 2)
        uP = rng.uniform(-2, 2)
        psi, psid = alpha + thP, ad + thPd
        M = np.array([[(p["m_S"] + mY + mP) * r**2 + JS + JYy, -mP * r * l / 2 * np.cos(psi)],
                      [-mP * r * l / 2 * np.cos(psi), mP * l**2 / 3]])
        Q = np.array([-p["k_S"] * ad - uP + p["k_P"] * thPd, uP - p["k_P"] * thPd])
        f = np.array([mP * r * l / 2 * np.sin(psi) * psid**2, mP * g * l / 2 * np.sin(psi)])
        add, psidd = np.linalg.solve(M, Q - f)
        x = ref.make_state(R_S=_ry(alpha), theta_P=thP, omega_S=(0.0, ad, 0.0), omega_P=thPd, r=r)
        expected = np.array([0.0, add, 0.0, 0.0, psidd - add])
        np.testing.assert_allclose(model.accel(x, (0.0, uP)), expected, atol=1e-10)


def test_accel_batch_agrees_with_accel_state_by_state(model, rng):
    X = np.array([_random_state(rng, model.params["r"]) for _ in range(6)])
    U = rng.uniform(-1.0, 1.0, size=(6, 2))
    A = model.accel_batch(X, U)
    assert A.shape == (6, 5)
    for x, u, a in zip(X, U, A):
        assert np.abs(a - model.accel(x, u)).max() <= 1e-12 * np.abs(a).max()


def test_accel_batch_names_a_wrong_shape(model):
    with pytest.raises(ValueError, match="shapes"):
        model.accel_batch(np.zeros((3, 35)), np.zeros((2, 2)))
