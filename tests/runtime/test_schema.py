"""runtime/schema.py: the one checker of the TOML tables of scenario, task and sweep files, and of
the ranges of their numbers."""
import pytest

from runtime.schema import Range, check_range, check_ranges, check_table, ranges_markdown


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


# -- ranges ------------------------------------------------------------------------------------
@pytest.mark.parametrize("value", [0.5, 1.0, 2.0])
def test_a_closed_range_holds_its_ends(value):
    assert check_range(value, Range(0.5, 2.0, "m"), "f: size") == value


@pytest.mark.parametrize("value", [0.4999999, 2.0000001])
def test_a_value_beyond_either_end_is_refused_with_the_key_and_the_range(value):
    with pytest.raises(ValueError, match=rf"^f: size: expected a number in \[0.5, 2\] m, got {value!r} \(why\)$"):
        check_range(value, Range(0.5, 2.0, "m", "why"), "f: size")


def test_an_open_low_end_is_itself_refused():
    rng = Range(0.0, 1.0, "s", open_low=True)
    assert check_range(5e-324, rng, "dt") == 5e-324
    with pytest.raises(ValueError, match=r"dt: expected a number in \(0, 1\] s, got 0.0"):
        check_range(0.0, rng, "dt")


def test_a_whole_range_refuses_a_fraction_inside_it():
    rng = Range(1, 100, whole=True)
    assert check_range(100, rng, "n") == 100 and check_range(3.0, rng, "n") == 3.0
    with pytest.raises(ValueError, match=r"n: expected a whole number in \[1, 100\], got 2.5"):
        check_range(2.5, rng, "n")


@pytest.mark.parametrize("value", ["text", True, float("nan"), float("inf"), None])
def test_what_is_not_a_finite_number_is_left_to_the_type_checks(value):
    assert check_range(value, Range(0, 1), "x") is value


def test_ranges_name_the_entry_of_a_list_and_skip_keys_without_a_range():
    table = {"q": [[0.0, 1.0], [0.5, 7.0]], "other": 1e300}
    with pytest.raises(ValueError, match=r"^f: reference.q\[1\]\[1\]: expected a number in \[-1, 1\] m"):
        check_ranges(table, {"q": Range(-1, 1, "m")}, "f: reference")
    assert check_ranges({"other": 1e300}, {"q": Range(-1, 1)}, "f") == {"other": 1e300}


def test_a_top_level_key_is_joined_to_the_file_by_a_colon():
    with pytest.raises(ValueError, match=r"^f.toml: dt: expected"):
        check_ranges({"dt": 5.0}, {"dt": Range(0, 1)}, "f.toml", sep=": ")


def test_the_markdown_table_lists_every_key_with_its_range_and_reason():
    text = ranges_markdown({"": {"dt": Range(1e-9, 1, "s", "a step")},
                            "reference": {"size": Range(0.05, 1e3, "m", "a lobe")}})
    assert text.splitlines()[2:] == ["| `dt` | a number in [1e-09, 1] s | a step |",
                                     "| `reference.size` | a number in [0.05, 1000] m | a lobe |"]
