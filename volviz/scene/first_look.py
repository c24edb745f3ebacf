"""What the first look says about what it draws (issue #30: never a blank first image, and never a silent one).

``volviz.model.representation`` decides how a dataset is drawn; here a scene about to be prepared acts on it: a time
series whose first step is constant opens at the first step where its field varies, and a constant field, or a series
moved to a later step, is said once as a ``FirstLookWarning`` naming the file (the app's status bar shows read
warnings of the files it shows, ``volviz render`` prints them as one line each).
"""
from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, Optional

from volviz.io import ReadWarning
from volviz.model import TimeSeries
from volviz.model.object_cache import ObjectCache
from volviz.model.representation import first_varying_step, representation
from volviz.scene.datasets import component_dataset
from volviz.scene.lod import is_lod
from volviz.session import Session

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.scene.datasets import LoadedDataset

#: per dataset, the notes already given ("step", "constant"), kept while it lives: each is said once
_SAID: ObjectCache[set[str]] = ObjectCache()


class FirstLookWarning(ReadWarning):
    """The first look draws a dataset other than as a volume of its first step: a constant field (as a surface), a
    time series from its first step where the field varies."""


def first_look(session: Session, datasets: dict[str, LoadedDataset], t: Optional[float]) -> Optional[float]:
    """The display time to prepare the scene at: ``t``, or for a time series shown at its first step (``t`` None or
    that step, and the session's display time none or that step: a series member opened first) whose field is
    constant there, the first step where it varies (kept as the session's display time). Says so, and says which
    shown fields are constant, once per dataset."""
    for comp in session.components:
        if not comp.visible or comp.type != "volume" or comp.dataset not in datasets:
            continue
        dataset = component_dataset(comp, datasets)
        if is_lod(dataset):   # a volume at a level of detail: always drawn as a volume, nothing to say
            continue
        # the path its reader read (as the user gave it, absolute from a session file; a series' first file), as
        # read warnings name it: the stored path is relative to the session file (issue #28: "../../work/shared/...")
        source = (dataset.frame(0) if isinstance(dataset, TimeSeries) else dataset).source
        path = source or next((ref.path for ref in session.datasets if ref.id == comp.dataset), comp.dataset)
        said = _SAID.setdefault(dataset, set)
        if isinstance(dataset, TimeSeries):
            first = float(dataset.times[0])
            start = session.render.options.get("time", first)
            at_first = (t is None or float(t) == first) and isinstance(start, (int, float)) and float(start) == first
            step = first_varying_step(dataset) if at_first else 0
            if step:
                t = float(dataset.times[step])
                session.render.options["time"] = t
                if "step" not in said:
                    said.add("step")
                    warnings.warn(FirstLookWarning(
                        f"{path}: {representation(dataset).field} is constant at the first time step; showing step "
                        f"{step + 1} of {len(dataset)} (time {t:g}), the first where it varies"), stacklevel=2)
        shown = representation(dataset)
        if shown.constant and "constant" not in said:
            said.add("constant")
            warnings.warn(FirstLookWarning(f"{path}: {shown.reason}"), stacklevel=2)
    return t
