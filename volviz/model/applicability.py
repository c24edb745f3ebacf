"""Which settings of a component apply to the dataset it shows.

Some settings do something only for some datasets: a volume's block budget only for a compressed ``.vvz`` volume
drawn at a view-dependent level of detail (``volviz.render.lod_volume``), "Interpolate in time" only for a time
series. Such a field carries the marker ``json_schema_extra={"applies_to": TRAIT}`` in its settings model
(``volviz.model.settings``; a list of traits: it applies when the dataset has any of them); a field without the
marker applies to every dataset. ``DatasetTraits`` describes a dataset by the traits these markers name, and
``applicable_fields`` lists the fields of a component type that apply to it. The app's settings form shows only
those; a value a session sets for a field that does not apply stays in the settings, unused.
"""
from __future__ import annotations

import typing
from dataclasses import dataclass
from typing import Literal, Optional

from pydantic.fields import FieldInfo

from volviz.model.settings import APPLIES_TO, settings_model

__all__ = ["DatasetTrait", "DATASET_TRAITS", "DatasetTraits", "field_traits", "applicable_fields"]

#: what a dataset may be, as far as some settings care: a time series (``volviz.model.TimeSeries``), or a compressed
#: volume drawn at a view-dependent level of detail (a ``.vvz`` opened with the dataset option ``lod``)
DatasetTrait = Literal["time_series", "lod_volume"]
DATASET_TRAITS: tuple[str, ...] = typing.get_args(DatasetTrait)


@dataclass(frozen=True)
class DatasetTraits:
    """What a component's dataset is, for the settings that apply to some datasets only (``DATASET_TRAITS``; the
    scene layer describes a loaded dataset: ``volviz.scene.datasets.dataset_traits``)."""

    time_series: bool = False
    lod_volume: bool = False

    def has(self, trait: str) -> bool:
        """Whether the dataset has ``trait`` (ValueError for a name that is not in ``DATASET_TRAITS``)."""
        if trait not in DATASET_TRAITS:
            raise ValueError(f"unknown dataset trait {trait!r}: expected one of {', '.join(DATASET_TRAITS)}")
        return bool(getattr(self, trait))


def field_traits(info: FieldInfo) -> tuple[str, ...]:
    """The traits a settings field's ``applies_to`` marker names (empty: the field applies to every dataset);
    ValueError for a marker that is not a trait or a list of traits."""
    extra = info.json_schema_extra
    marker = extra.get(APPLIES_TO) if isinstance(extra, dict) else None
    wanted = [] if marker is None else [marker] if isinstance(marker, str) else marker
    if not isinstance(wanted, list) or any(trait not in DATASET_TRAITS for trait in wanted):
        raise ValueError(f"{APPLIES_TO} {marker!r}: expected one of {', '.join(DATASET_TRAITS)} or a list of them")
    return tuple(str(trait) for trait in wanted)


def applicable_fields(component_type: str, traits: Optional[DatasetTraits]) -> tuple[str, ...]:
    """The names of the fields of ``component_type``'s settings model (in the model's order) that apply to a dataset
    with ``traits``: those without an ``applies_to`` marker, and those whose marker names a trait the dataset has.
    ``traits`` None (a dataset not known yet, e.g. not read): every field. KeyError for an unknown component type,
    ValueError for a marker that names no trait (``field_traits``)."""
    names = []
    for name, info in settings_model(component_type).model_fields.items():
        wanted = field_traits(info)
        if not wanted or traits is None or any(traits.has(trait) for trait in wanted):
            names.append(name)
    return tuple(names)
