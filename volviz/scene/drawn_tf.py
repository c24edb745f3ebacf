"""The transfer function a component is drawn with: the session's, through log10 when the component's setting
``log_scale`` is on (``volviz.optics.log_scale``). The session and the TF editor keep the function in data values;
only what the renderers and the scalar bar are given changes."""
from __future__ import annotations

import weakref
from typing import TYPE_CHECKING, Any, Optional

import numpy as np

from volviz.model.stats import scalar_values
from volviz.optics.log_scale import log_mapped, positive_floor
from volviz.scene.lod import is_lod, lod_scalar_range
from volviz.session import Component, Session

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.optics.transfer_function import TransferFunction

_FLOORS: dict[int, tuple[Any, float]] = {}   # id(dataset) -> (weak reference to it, its smallest positive value)


def uses_log_scale(comp: Component) -> bool:
    """Whether the component maps its scalar through log10 (the setting ``log_scale``)."""
    return bool(comp.settings.get("log_scale", False))


def log_floor(tf: TransferFunction, dataset: object) -> float:
    """The smallest positive value the log scale of ``tf`` over ``dataset``'s shown array maps (values at or below
    it take its color): the TF's low end when positive, else the data's smallest positive value (cached per
    dataset: one pass over the values)."""
    lo, hi = tf.range
    if lo > 0:
        return float(lo)
    cached = _FLOORS.get(id(dataset))
    if cached is not None and cached[0]() is dataset:
        return cached[1]
    floor = positive_floor(_values(dataset), lo, hi)
    try:
        _FLOORS[id(dataset)] = (weakref.ref(dataset), floor)
    except TypeError:   # an object without weak references: not cached
        pass
    return floor


def _values(dataset: Any) -> np.ndarray:
    if is_lod(dataset):   # a compressed volume: the range of its finest level (no decoding)
        return np.asarray(lod_scalar_range(dataset), dtype=np.float64)
    try:
        return scalar_values(dataset)
    except TypeError:
        return np.zeros(0)


def drawn_tf(comp: Component, tf: Optional[TransferFunction], dataset: object) -> Optional[TransferFunction]:
    """``tf`` (the component's stored function) as the component is drawn with it over ``dataset``."""
    if tf is None or not uses_log_scale(comp):
        return tf
    return log_mapped(tf, log_floor(tf, dataset))



def component_transfer_function(session: Session, comp: Component) -> Optional[TransferFunction]:
    """The component's stored transfer function (in data values), or None when it has none."""
    if comp.transfer_function is None:
        return None
    return session.transfer_functions[comp.transfer_function]


def drawn_transfer_function(session: Session, comp: Component, dataset: object) -> Optional[TransferFunction]:
    """The component's transfer function as drawn (through log10 with the setting ``log_scale``)."""
    return drawn_tf(comp, component_transfer_function(session, comp), dataset)
