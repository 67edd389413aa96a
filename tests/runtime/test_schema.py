"""runtime/schema.py: the one checker of the TOML tables of scenario, task and sweep files."""
import pytest

from runtime.schema import check_table


def test_a_table_of_allowed_keys_is_returned_as_it_is():
    table = {"dt": 0.01, "steps": 10}
    assert check_table(table, {"dt", "steps", "method"}, "f.toml") is table


def test_an_unknown_key_is_named_with_the_allowed_ones():
    with pytest.raises(ValueError, match=r"^f\.toml: initial: unknown key 'R_X'; allowed: R_S, theta_P$"):
        check_table({"R_X": 1, "theta_P": 0.1}, {"R_S", "theta_P"}, "f.toml: initial")


def test_several_unknown_keys_are_all_named_in_order():
    with pytest.raises(ValueError, match=r"unknown keys 'a', 'b'; allowed: c$"):
        check_table({"b": 1, "a": 2}, {"c"}, "where")


@pytest.mark.parametrize("value, shown", [(3, "int 3"), ([1, 2], r"list \[1, 2\]"), ("x" * 100, "str 'x{56}\\.\\.\\.")])
def test_a_value_that_is_not_a_table_is_named_by_type_and_value(value, shown):
    with pytest.raises(ValueError, match=rf"^where: expected a table, got {shown}"):
        check_table(value, {"c"}, "where")
