"""The log color scale in the window: when the component selected in the scene tree is drawn with its setting
``log_scale``, the TF editor's scalar axis is in log10 from the scale's smallest positive value (``log_floor``),
and the status bar says how many values at or below 0 the scale cannot map and draws in that value's color
(``volviz.optics.log_scale``); with the setting off the axis is linear again. Updated at each selection and at
each scene shown (a settings edit rebuilds the scene)."""
from __future__ import annotations

from typing import Any, Optional

STATUS_MS = 20000     # how long the status bar shows the note on clamped values


def clamp_note(comp_id: str, dataset: Any, floor: float) -> Optional[str]:
    """The status bar's line on the values of ``dataset`` a log scale clamps to ``floor``; None when none is."""
    from volviz.optics.log_scale import clamped_count
    from volviz.regular.lod import LodTree

    drawn = f"drawn in the color of {floor:g}, the smallest positive value (log color scale of {comp_id})"
    if isinstance(dataset, LodTree):     # a compressed volume: its range (no decoding)
        from volviz.scene.lod import lod_scalar_range

        low = lod_scalar_range(dataset)[0]
        return f"Values from {low:g} to 0 are {drawn}" if low <= 0 else None
    from volviz.model.stats import scalar_values

    try:
        count = clamped_count(scalar_values(dataset))
    except TypeError:                    # a dataset without scalars
        return None
    return f"{count:,} values ≤ 0 are {drawn}" if count else None


class LogScaleStatus:
    """Connects the scene tree's selection to the TF editor's axis and the status bar (module docstring);
    ``note`` is the last note shown ("" for none)."""

    def __init__(self, window: Any) -> None:
        self.window = window
        self.note = ""
        window.scene_tree.componentSelected.connect(self.update)
        window.scene_tree.populated.connect(lambda: self.update(window.scene_tree.current_component()))

    def update(self, comp_id: Optional[str]) -> None:
        """Show the axis and the note for component ``comp_id`` (None: none selected)."""
        from volviz.scene.drawn_tf import log_floor, uses_log_scale

        window, floor = self.window, None
        controller = window.controller
        if controller is not None and comp_id is not None:
            comp = next((c for c in controller.session.components if c.id == comp_id), None)
            tf = controller.transfer_function(comp_id) if comp is not None and uses_log_scale(comp) else None
            if tf is not None and comp is not None and comp.dataset in controller.datasets:
                dataset = controller.dataset_of(comp_id)
                floor = log_floor(tf, dataset)
                note = clamp_note(comp_id, dataset, floor) if tf.range[0] <= 0 else None
                if note:
                    window.statusBar().showMessage(note, STATUS_MS)
                self.note = note or ""
        if floor is None:
            self.note = ""
        window.tf_editor.set_log_axis(floor)
