"""``volviz.render.error_budget``: which table options the app switches to, or what it says, when the measured
error of a PT view exceeds the render option ``error_budget``."""
from __future__ import annotations

from volviz.render.error_budget import MOST_ACCURATE_TABLE, BudgetChoice, error_budget_choice


def test_within_the_budget_nothing_changes() -> None:
    assert error_budget_choice(0.5, {"error_budget": 0.5}) == BudgetChoice(None, None)
    assert error_budget_choice(0.99, {}) == BudgetChoice(None, None)  # the default budget: 1.0
    assert error_budget_choice(3.0, {"error_budget": 4.0, "table": "auto"}) == BudgetChoice(None, None)


def test_above_the_budget_the_most_accurate_table_once() -> None:
    choice = error_budget_choice(1.234, {"error_budget": 0.5, "table": "auto", "table_resolution": 128})
    assert choice.table == {"table": "separable-4", "table_resolution": 512}
    assert choice.message == ("Measured error 1.23 exceeds the budget 0.50: switching to the degree-4 separable "
                              "table at 512²")
    # half of it on is not the most accurate table yet
    assert error_budget_choice(2.0, {"error_budget": 1.0, "table": "separable-4"}).table == MOST_ACCURATE_TABLE
    assert error_budget_choice(1.01, {}).message == ("Measured error 1.01 exceeds the budget 1.00: switching to the "
                                                     "degree-4 separable table at 512²")


def test_with_the_finest_table_only_a_message() -> None:
    choice = error_budget_choice(2.5, {"error_budget": 0.0, "table": "separable-4", "table_resolution": 512})
    assert choice == BudgetChoice(None, "Measured error 2.50 exceeds the budget 0.00 even with the finest table; "
                                        "the exact 'reference' renderer meets any budget")


def test_the_choice_is_a_copy() -> None:
    choice = error_budget_choice(9.0, {"error_budget": 1.0})
    choice.table["table_resolution"] = 16
    assert MOST_ACCURATE_TABLE == {"table": "separable-4", "table_resolution": 512}


def test_a_budget_of_none_is_the_default() -> None:
    """The settings model's default for ``error_budget`` is None (a session may say ``"error_budget": null``)."""
    assert error_budget_choice(0.9, {"error_budget": None}) == BudgetChoice()
    assert error_budget_choice(1.5, {"error_budget": None}).table == MOST_ACCURATE_TABLE


def test_vtks_projected_tetrahedra_get_a_message_and_no_table() -> None:
    """The render method "vtk" (VTK's projected tetrahedra, drawn as a PT view's image) has no table of ours: the
    finest table would change nothing it draws, and the user's table settings stay."""
    choice = error_budget_choice(3.1, {"error_budget": 1.0, "table": "auto"}, "vtk")
    assert choice == BudgetChoice(None, "Measured error 3.10 of VTK's projected tetrahedra exceeds the budget 1.00; "
                                        "volviz's 'pt' renderer adapts its table to the budget and the exact "
                                        "'reference' renderer meets any budget")
    assert error_budget_choice(0.8, {"error_budget": 1.0}, "vtk") == BudgetChoice()
    assert error_budget_choice(3.1, {"error_budget": 1.0}, "pt").table == MOST_ACCURATE_TABLE
