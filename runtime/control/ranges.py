"""The ranges of the controllers' and the estimator's settings: one table per kind, read both by the
task files' loader (runtime/control/task.py's TASK_RANGES) and by the constructors (`PidGains`,
`LqrGains`, `NmpcGains`, `EkfSettings`, and every controller's rate and u_max), so that a value a
task file may not hold is refused by the Python API too, with the argument named."""
from bindings._sr import lib

from ..schema import Range

#: Every controller's sampling rate and torque limit (`[controller]` rate, u_max; `Controller`).
CONTROLLER_RANGES = {
    "rate": Range(0.01, 1e4, "Hz", "a sampling rate: its period is a whole number of steps dt"),
    "u_max": Range(1e-6, 100, "N m", "a torque limit: the paper's motors give 0.5-2 N m"),
}

_ERROR_SIZE = Range(1e-6, 1e6, "", "a Bryson error size (its unit: the key's); 0 or a huge one makes the Riccati "
                    "weights singular")
_PID_GAIN = Range(0, 1e6, "", "a gain (its unit: docs/control.md)")

#: `PidGains`.
PID_RANGES = {**{name: _PID_GAIN for name in ("k_v", "k_vi", "k_y", "k_psi", "k_r", "k_ri", "k_phi", "k_phii",
                                              "k_phid")},
              "phi_max": Range(0, 1.5, "rad", "a lean short of lying on the side")}

#: `LqrGains`.
LQR_RANGES = {
    **{name: _ERROR_SIZE for name in ("tilt_rad", "attitude_rad", "pendulum_rad", "rolling_rate_rad_s", "rate_rad_s",
                                      "joint_rate_rad_s", "cross_track_m", "cross_track_integral_m_s",
                                      "speed_integral_rad", "tight_cross_track_m")},
    "heading_rad": Range(0, 1e6, "rad", "the heading's own Bryson size (0: attitude_rad's)"),
    "v_min": Range(0, 10, "m/s", "the design grid's speeds"), "v_max": Range(0, 10, "m/s", "the design grid's speeds"),
    "n_speeds": Range(1, lib.SR_LQR_MAX_SPEEDS, "", "the C controller's grid holds SR_LQR_MAX_SPEEDS", whole=True),
    "kappa_max": Range(0, 100, "1/m", "a turn of 1 cm radius at most"),
    "n_curvatures": Range(1, lib.SR_LQR_MAX_CURVATURES, "", "the C controller's grid holds SR_LQR_MAX_CURVATURES",
                          whole=True),
    "kappa_rate": Range(0, 1e4, "1/(m s)", "how fast the operating point may follow the path"),
    "preview_m": Range(0, 100, "m", "a preview along the path"),
    "smoothing_m": Range(0, 100, "m", "a smoothing window along the path"),
    "steady_rate_m_s": Range(0, 10, "m/s", "a rate of the cross-track error"),
    "slope_estimate_s": Range(0, 1e4, "s", "the slope estimate's time constant (0: no estimate)"),
    "pendulum_feedforward": Range(0, 1, "", "the share of the estimated pendulum's steady torques fed forward"),
    "slope_prior": Range(0, 1e3, "", "the slope estimate's prior, times its standard deviations (0: unweighted)"),
    "tight_band_m": Range(0, 100, "m", "how near the path the tight gains act (0: not at all)"),
    "tight_rise_s": Range(1e-3, 1e4, "s", "how slowly the tight gains come in"),
    "world_share": Range(0, 1, "", "the share of the cross-track integral held in the world frame"),
    "tight_fall_s": Range(0, 1e4, "s", "how fast the tight gains leave after a clipped torque (0: they hold)"),
    "tight_wait": Range(0, 1, "", "how far below 0 their weight falls after a clip (a wait before they return)"),
    "heading_band_rad": Range(0, 3.2, "rad", "how near the heading the stiffer heading gains act (0: not at all)"),
    "tight_heading_rad": _ERROR_SIZE,
    "heading_rise_s": Range(1e-3, 1e4, "s", "how slowly the stiffer heading gains come in"),
    "recovery_cross_track_m": Range(0, 100, "m", "the cross-track error the law acts on at most (0: unbounded)"),
    "recovery_heading_rad": Range(0, 3.2, "rad", "the heading error the law acts on at most (0: unbounded)"),
    "recovery_slow": Range(0, 0.9, "", "the share of the speed reference given up while recovering (below 1)"),
    "recovery_rise_s": Range(1e-3, 1e4, "s", "how slowly the recovery's speed change comes in and goes"),
}

#: `NmpcGains`: the LQR's and the horizon's.
NMPC_RANGES = {
    **LQR_RANGES,
    "tight_band_m": Range(0, 0, "m", "the NMPC has no tight gains (an LQR setting): 0 only"),
    "world_share": Range(0, 0, "", "the NMPC holds no world-frame integral (an LQR setting): 0 only"),
    "pendulum_feedforward": Range(0, 0, "", "the NMPC feeds no pendulum forward (an LQR setting): 0 only"),
    "slope_prior": Range(0, 0, "", "the NMPC's slope estimate is unweighted (an LQR setting): 0 only"),
    "heading_band_rad": Range(0, 0, "rad", "the NMPC has no scheduled heading gains (an LQR setting): 0 only"),
    **{name: Range(0, 0, "", "the NMPC has no recovery mode (an LQR setting): 0 only")
       for name in ("recovery_cross_track_m", "recovery_heading_rad", "recovery_slow")},
    "torque_step_n_m": Range(1e-6, 1e6, "N m", "a torque change worth the full cost"),
    "disturbance_gain": Range(0, 1, "", "the share of the torque offset's update taken per sample (0: no estimate)"),
    "horizon": Range(1, 200, "", "nodes of the horizon: the QP has 2N unknowns and a dense (2N)^2 Hessian",
                     whole=True),
    "node_periods": Range(1, 100, "", "controller periods per node", whole=True),
    "iterations": Range(1, 100, "", "real-time iterations per sample: each solves a QP", whole=True),
}

#: `NmpcGains` of the C NMPC (kind nmpc-c): its horizon within the capacity of its buffers.
NMPC_C_RANGES = {
    **NMPC_RANGES,
    "horizon": Range(1, lib.SR_NMPC_MAX_HORIZON, "", "nodes of the horizon: the C NMPC's buffers hold "
                     "SR_NMPC_MAX_HORIZON (c/include/sr_nmpc.h; set at build time)", whole=True),
}

#: `EkfSettings`.
ESTIMATOR_RANGES = {
    "position_m": Range(1e-9, 1e3, "m", "a standard deviation"),
    "attitude_rad": Range(1e-9, 10, "rad", "a standard deviation"),
    "joint_rad": Range(1e-9, 10, "rad", "a standard deviation"),
    "rate_rad_s": Range(1e-9, 1e3, "rad/s", "a standard deviation"),
    "accel_rad_s2": Range(1e-9, 1e4, "rad/s^2/sqrt(Hz)", "a process noise"),
    "rate": Range(0, 1e5, "Hz", "the sensors' rate (0: the controller's)"),
}
