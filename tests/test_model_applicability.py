"""Settings that apply to some datasets only (issue #18): the ``applies_to`` markers of the settings models, the
fields ``applicable_fields`` names for each kind of dataset, and how the render layer describes a loaded dataset."""
from __future__ import annotations

from dataclasses import fields
from pathlib import Path

import numpy as np
import pytest
from pydantic import Field

from conftest import blob_vvz
from volviz.model import RegularVolume, TimeSeries
from volviz.model.applicability import DATASET_TRAITS, DatasetTraits, applicable_fields, field_traits
from volviz.model.demo import demo_tet_mesh
from volviz.model.settings import SETTINGS_MODELS
from volviz.render.controller import SceneController
from volviz.scene.datasets import dataset_traits, read_any
from volviz.session import Component, DatasetRef, Session

PLAIN = DatasetTraits()
SERIES = DatasetTraits(time_series=True)
LOD = DatasetTraits(lod_volume=True)
EVERYTHING = DatasetTraits(time_series=True, lod_volume=True)
ISO_FIELDS = ("styles", "mode", "shading", "clip", "lod", "triangles_per_pixel2", "interpolate", "scalars")


def test_the_marked_fields_and_their_traits() -> None:
    assert tuple(f.name for f in fields(DatasetTraits)) == DATASET_TRAITS == ("time_series", "lod_volume")
    marked = {(kind, name): field_traits(info) for kind, model in SETTINGS_MODELS.items()
              for name, info in model.model_fields.items() if field_traits(info)}
    assert marked == {("volume", "budget"): ("lod_volume",), ("volume", "interpolate"): ("time_series",),
                      ("mesh", "budget"): ("lod_volume",), ("mesh", "interpolate"): ("time_series",),
                      ("isosurface", "interpolate"): ("time_series",)}


@pytest.mark.parametrize("kind", ["volume", "mesh"])
def test_volume_fields_by_dataset(kind: str) -> None:
    # (log_scale, the log color scale, applies to every dataset)
    assert applicable_fields(kind, PLAIN) == ("array", "log_scale", "shade")      # a plain (e.g. tetrahedral) volume
    assert applicable_fields(kind, SERIES) == ("array", "interpolate", "log_scale", "shade")
    assert applicable_fields(kind, LOD) == ("array", "budget", "log_scale", "shade")
    assert applicable_fields(kind, EVERYTHING) == ("array", "budget", "interpolate", "log_scale", "shade")
    # not known: every field
    assert applicable_fields(kind, None) == ("array", "budget", "interpolate", "log_scale", "shade")


def test_isosurface_fields_by_dataset() -> None:
    assert applicable_fields("isosurface", PLAIN) == tuple(n for n in ISO_FIELDS if n != "interpolate")
    assert applicable_fields("isosurface", SERIES) == ISO_FIELDS
    assert applicable_fields("isosurface", LOD) == tuple(n for n in ISO_FIELDS if n != "interpolate")
    assert applicable_fields("isosurface", None) == ISO_FIELDS


@pytest.mark.parametrize("kind", ["terrain", "fog", "clouds", "sky", "demo"])
def test_unmarked_models_keep_every_field(kind: str) -> None:
    every = tuple(SETTINGS_MODELS[kind].model_fields)
    for traits in (PLAIN, SERIES, LOD, EVERYTHING, None):
        assert applicable_fields(kind, traits) == every


def test_bad_names_are_refused() -> None:
    with pytest.raises(KeyError):
        applicable_fields("hologram", PLAIN)
    with pytest.raises(ValueError, match="unknown dataset trait 'curvy'"):
        PLAIN.has("curvy")
    assert field_traits(Field(1, json_schema_extra={"applies_to": ["time_series", "lod_volume"]})) == \
        ("time_series", "lod_volume")
    assert field_traits(Field(1, json_schema_extra={"unit": "m"})) == ()
    for marker in ("curvy", ["time_series", "curvy"], 3):
        with pytest.raises(ValueError, match="applies_to"):
            field_traits(Field(1, json_schema_extra={"applies_to": marker}))


def test_loaded_datasets_are_described_by_the_render_layer(tmp_path: Path) -> None:
    vvz = blob_vvz(tmp_path / "blob.vvz", 16)
    volume = RegularVolume(np.zeros((2, 2, 2), dtype=np.uint8))
    assert dataset_traits(volume) == PLAIN
    assert dataset_traits(demo_tet_mesh(2)) == PLAIN
    assert dataset_traits(TimeSeries([0.0, 1.0], [volume, volume])) == SERIES
    assert dataset_traits(read_any(vvz, {"lod": True})) == LOD            # drawn by blocks per view
    assert dataset_traits(read_any(vvz, {})) == PLAIN                     # decoded whole: a regular volume


def test_controller_describes_each_components_dataset() -> None:
    volume = RegularVolume(np.zeros((2, 2, 2), dtype=np.uint8))
    session = Session(datasets=[DatasetRef("series", "s.pvm-t%02d"), DatasetRef("hidden", "h.vtu")],
                      components=[Component("series", "volume", dataset="series"),
                                  Component("hidden", "volume", dataset="hidden", visible=False),
                                  Component("sky", "sky")])
    controller = SceneController(None, session, {"series": TimeSeries([0.0, 1.0], [volume, volume])})
    assert controller.dataset_traits("series") == SERIES
    assert controller.dataset_traits("hidden") is None                    # not read yet
    assert controller.dataset_traits("sky") == PLAIN                      # no dataset
