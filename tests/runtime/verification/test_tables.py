"""The independent models keep their own parameter order and state layout on purpose; these must equal the
generated ones (SR_P_* and SR_X_* of generated/sr_generated.h, read from the compiled module)."""
import numpy as np

from bindings._sr import lib
from runtime.so3 import random_rotation
from runtime.state import initial_state
from runtime.verification import reference, sensor_reference
from runtime.verification.alternatives import kane


def generated_parameter_order():
    indices = {name[len("SR_P_"):]: getattr(lib, name) for name in dir(lib) if name.startswith("SR_P_")}
    return tuple(sorted(indices, key=indices.get))


def generated_paper_order():
    indices = {name[len("SR_PAPER_"):]: getattr(lib, name) for name in dir(lib) if name.startswith("SR_PAPER_")}
    return tuple(sorted(indices, key=indices.get))


def flattened(names):
    """The reference's grouped names (c_Y, J_Y, ...) as the entries of the C vector."""
    out = []
    for n in names:
        if n.startswith("c_"):
            out += [f"{n}_{a}" for a in "xyz"]
        elif n.startswith("J_"):
            out += [f"{n}_{k}" for k in ("xx", "yy", "zz", "xy", "xz", "yz")]
        else:
            out.append(n)
    return tuple(out)


def generated_state_offsets():
    return {name[len("SR_X_"):]: getattr(lib, name) for name in dir(lib) if name.startswith("SR_X_")}


def layout_mismatches(param_names, state_dim, offsets):
    """What differs between a model's own tables and the generated ones (empty when they agree)."""
    problems = []
    if tuple(param_names) != generated_parameter_order():
        problems.append(f"parameter order {tuple(param_names)} != {generated_parameter_order()}")
    if state_dim != lib.SR_NX:
        problems.append(f"state dimension {state_dim} != {lib.SR_NX}")
    generated = generated_state_offsets()
    if set(offsets) != set(generated):
        problems.append(f"blocks {sorted(offsets)} != {sorted(generated)}")
    problems += [f"{block} at {offset} != {generated[block]}" for block, offset in offsets.items()
                 if block in generated and offset != generated[block]]
    return problems


def test_the_generated_tables_are_complete():
    assert len(generated_parameter_order()) == lib.SR_NPARAM
    assert set(generated_state_offsets()) == {"R_S", "R_Y", "R_P", "q", "w_S", "w_Y", "w_P"}


def test_the_reference_tables_follow_the_generated_order():
    offsets = {"R_S": reference._RS.start, "R_Y": reference._RY.start, "R_P": reference._RP.start,
               "q": reference._Q.start, "w_S": reference._WS.start, "w_Y": reference._WY, "w_P": reference._WP}
    assert layout_mismatches(flattened(reference.PARAM_NAMES), reference.STATE_DIM, offsets) == []
    assert reference._NU.start == lib.SR_X_w_S
    assert reference.PAPER_PARAM_NAMES == generated_paper_order()


def test_the_kane_tables_follow_the_generated_order():
    offsets = {"R_S": kane.X_R_S, "R_Y": kane.X_R_Y, "R_P": kane.X_R_P, "q": kane.X_Q,
               "w_S": kane.X_NU, "w_Y": kane.X_NU + 3, "w_P": kane.X_NU + 4}
    assert layout_mismatches(kane.GENERAL_PARAM_NAMES, kane.STATE_DIM, offsets) == []
    assert kane.PARAM_NAMES == generated_paper_order()


def sensor_layout_mismatches(bodies, mount, imu_dim, bias_dim, error_dim):
    """What differs between the sensor reference's tables and the generated SR_BODY_*, SR_MOUNT_*, sizes."""
    problems = [f"body {b} at {i} != {getattr(lib, f'SR_BODY_{b}', None)}" for i, b in enumerate(bodies)
                if getattr(lib, f"SR_BODY_{b}", None) != i]
    problems += [f"mount {k} at {v} != {getattr(lib, f'SR_MOUNT_{k}')}" for k, v in mount.items()
                 if getattr(lib, f"SR_MOUNT_{k}") != v]
    sizes = {"imu": (imu_dim, lib.SR_NIMU), "bias": (bias_dim, lib.SR_NBIAS), "error": (error_dim, lib.SR_NE)}
    problems += [f"{k} size {ours} != {theirs}" for k, (ours, theirs) in sizes.items() if ours != theirs]
    return problems


def test_the_sensor_reference_tables_follow_the_generated_order():
    s = sensor_reference
    mount = {"lever": s.MOUNT_LEVER.start, "R_m": s.MOUNT_ROTATION.start}
    assert s.MOUNT_DIM == lib.SR_NMOUNT and lib.SR_NBODY == len(s.BODIES)
    assert (lib.SR_IMU_gyro, lib.SR_IMU_accel, lib.SR_BIAS_b_g, lib.SR_BIAS_b_a) == (0, 3, 0, 3)
    assert (lib.SR_EB_b_g, lib.SR_EB_b_a, lib.SR_NEB) == (s.ERROR_DIM, s.ERROR_DIM + 3, s.ERROR_DIM + s.BIAS_DIM)
    assert sensor_layout_mismatches(s.BODIES, mount, s.IMU_DIM, s.BIAS_DIM, s.ERROR_DIM) == []


def test_a_swapped_sensor_table_is_reported():
    s = sensor_reference
    problems = sensor_layout_mismatches(("yoke", "shell", "pendulum"), {"lever": 3, "R_m": 0}, 6, 6, 12)
    assert len(problems) == 4


def test_a_swapped_table_is_reported():
    names = list(flattened(reference.PARAM_NAMES))
    names[0], names[1] = names[1], names[0]
    offsets = dict(generated_state_offsets(), w_Y=lib.SR_X_w_P, w_P=lib.SR_X_w_Y)
    problems = layout_mismatches(names, lib.SR_NX, offsets)
    assert len(problems) == 3 and "parameter order" in problems[0]
    assert layout_mismatches(flattened(reference.PARAM_NAMES), lib.SR_NX + 1, generated_state_offsets()) != []


def test_the_reference_builds_the_same_state_as_the_runtime(rng):
    R_S = random_rotation(rng)
    ours = initial_state(0.3, -1.1, R_S=R_S, q=(0.5, -0.25, 0.4), w_S=(1.0, 2.0, 3.0), w_Y=4.0, w_P=5.0, r=0.4)
    theirs = reference.make_state(R_S=R_S, theta_Y=0.3, theta_P=-1.1, q_xy=(0.5, -0.25), omega_S=(1.0, 2.0, 3.0),
                                  omega_Y=4.0, omega_P=5.0, r=0.4)
    assert np.array_equal(ours, theirs)


def test_the_kane_model_reads_the_runtime_state_by_its_blocks():
    x = initial_state(0.3, -1.1, q=(0.5, -0.25, 0.3), w_S=(1.0, 2.0, 3.0), w_Y=4.0, w_P=5.0)
    coordinates, speeds = kane.KaneModel.coordinates(x)
    assert np.allclose(coordinates, (0.0, 0.0, 0.0, 0.3, -1.1, 0.5, -0.25), atol=1e-15)
    assert speeds == (1.0, 2.0, 3.0, 4.0, 5.0)
