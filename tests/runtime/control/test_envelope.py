"""The envelope's friction table (runtime/control/envelope.py): the friction each benchmark run needs."""
from runtime.control.envelope import friction_table, task_friction


def test_the_friction_table_has_a_row_per_controller_of_a_task_with_the_largest_ratio_of_its_run():
    rows = task_friction(["speed-step"], duration=0.5)
    assert [(task, kind) for task, kind, *_ in rows] == [("speed-step", "pid"), ("speed-step", "lqr"),
                                                        ("speed-step", "nmpc")]
    assert all(0 < ratio < 1 and 0 <= t <= 0.5 and fn > 0 for _, _, ratio, t, fn in rows)
    table = friction_table(rows).splitlines()
    assert len(table) == 2 + len(rows) and table[2].startswith("| speed-step | pid | ")
