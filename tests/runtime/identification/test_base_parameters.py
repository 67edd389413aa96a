"""docs/identification.md's base-parameter table is the one the code computes (python -m runtime
base-parameters --write keeps it current)."""
import pathlib

from runtime.identification import base_parameters

DOC = pathlib.Path(__file__).resolve().parents[3] / "docs" / "identification.md"


def table_in(text):
    _, rest = text.split(base_parameters.TABLE_BEGIN, 1)
    return rest.split(base_parameters.TABLE_END, 1)[0].lstrip("\n")


def test_the_base_parameter_table_of_the_docs_is_current():
    assert table_in(DOC.read_text()) == base_parameters.base_parameter_table()


def test_the_table_check_fails_for_an_edited_value():
    text = DOC.read_text()
    table = table_in(text)
    edited = table.replace("| `", "| `x", 1)
    assert edited != table and table_in(text.replace(table, edited)) != base_parameters.base_parameter_table()
