"""The error budget of volviz's PT renderer: what to do when the measured error of the current view (RMSE in 8-bit
units against the exact reference, ``PTVolume.error_estimate``) exceeds the render option ``error_budget``.

The answer is a ``BudgetChoice``: within the budget nothing; above it (for volviz's PT), once, the most accurate
pre-integration table (the degree-4 separable table at 512², ``MOST_ACCURATE_TABLE``), and a message that says so;
with that table already on, only a message that the budget cannot be met. The app applies the choice
(``app/view_scheduler.py``)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping, Optional

from volviz.model.json_types import json_float

MOST_ACCURATE_TABLE: dict[str, Any] = {"table": "separable-4", "table_resolution": 512}
DEFAULT_BUDGET = 1.0  # RMSE of 8-bit units, when the options name none


@dataclass(frozen=True)
class BudgetChoice:
    """``table``: the render options to switch to (None: keep the current ones); ``message``: what to tell the
    user (None: the error is within the budget)."""

    table: Optional[dict[str, Any]] = None
    message: Optional[str] = None


def error_budget_choice(rmse: float, options: Mapping[str, object], method: str = "pt") -> BudgetChoice:
    """What to do about a measured error ``rmse`` under the render ``options`` (their ``error_budget``, ``table``
    and ``table_resolution``) of the render ``method``: VTK's projected tetrahedra ("vtk") have no table of ours to
    switch, so above the budget only a message names volviz's own renderers."""
    given = options.get("error_budget")
    budget = DEFAULT_BUDGET if given is None else json_float(given)   # None (the model's default): no budget set
    if rmse <= budget:
        return BudgetChoice()
    if method == "vtk":
        return BudgetChoice(message=f"Measured error {rmse:.2f} of VTK's projected tetrahedra exceeds the budget "
                                    f"{budget:.2f}; volviz's 'pt' renderer adapts its table to the budget and the "
                                    "exact 'reference' renderer meets any budget")
    if all(options.get(k) == v for k, v in MOST_ACCURATE_TABLE.items()):
        return BudgetChoice(message=f"Measured error {rmse:.2f} exceeds the budget {budget:.2f} even with the "
                                    "finest table; the exact 'reference' renderer meets any budget")
    return BudgetChoice(table=dict(MOST_ACCURATE_TABLE),
                        message=f"Measured error {rmse:.2f} exceeds the budget {budget:.2f}: switching to the "
                                "degree-4 separable table at 512²")
