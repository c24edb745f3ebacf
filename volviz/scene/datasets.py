"""A session's datasets read once each, and the dataset each component shows ("Model only what a scene needs": only
the datasets of shown components are read; an array choice is made once per dataset and kept while it lives)."""
from __future__ import annotations

import os
import weakref
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping, Optional, Union

from volviz.io import read
from volviz.jobs import ProgressCallback, report
from volviz.model import Dataset, Image2D, TimeSeries
from volviz.model.applicability import DatasetTraits
from volviz.model.demo import demo_tet_mesh
from volviz.model.json_types import json_int
from volviz.model.arrays import select_array
from volviz.model.representation import representation
from volviz.scene.errors import SceneError
from volviz.scene.lod import is_lod
from volviz.session import Component, Session, SessionError, missing_files, missing_message, resolve_path

if TYPE_CHECKING:   # type-only: the LOD tree's module loads the wavelet decoder's Numba kernels
    from volviz.regular.lod import LodTree

#: what a session's dataset id stands for once loaded (``load_datasets``): a model dataset, a time series of them,
#: or a compressed volume drawn at a level of detail
LoadedDataset = Union[Dataset, TimeSeries, "LodTree"]

#: the component types the natural scene draws together (``volviz.scene.nature``)
NATURE_TYPES = ("terrain", "fog", "clouds", "sky")


def load_datasets(session: Session, session_file: Optional[str | os.PathLike],
                  progress: Optional[ProgressCallback] = None,
                  loaded: Optional[dict[str, LoadedDataset]] = None,
                  also: tuple[str, ...] = ()) -> dict[str, LoadedDataset]:
    """Read every dataset that a visible component (or a component in ``also``) uses, once each, with progress;
    those already in ``loaded`` are kept (the dict is filled in and returned)."""
    used = {c.dataset for c in session.components if (c.visible or c.id in also) and c.dataset is not None}
    nature = [c for c in session.components if c.visible and c.type in NATURE_TYPES]
    if nature:
        from volviz.nature.nature_scene import nature_dataset_ids   # heavy (the nature kernels): only when shown

        used |= nature_dataset_ids(nature)
    loaded = {} if loaded is None else loaded
    refs = [ref for ref in session.datasets if ref.id in used and ref.id not in loaded]
    missing = missing_files(session, session_file, {ref.id for ref in refs})
    if missing:  # each one named at once, before any is read
        raise SessionError(session_file, missing_message(missing), field="datasets")
    for i, ref in enumerate(refs):
        report(progress, i / max(len(refs), 1), f"reading {Path(ref.path).name}")
        path = resolve_path(session_file, ref.path) if session_file else Path(ref.path)
        loaded[ref.id] = read_any(path, ref.options, progress)
    report(progress, 1.0, "datasets read")
    return loaded


def read_any(path: Path, options: Mapping[str, object], progress: Optional[ProgressCallback] = None
             ) -> LoadedDataset:
    """A data file through ``volviz.io.read``, or a volviz-compressed volume (``.vvz``): with the dataset option
    ``lod`` a ``LodTree`` drawn at a view-dependent level of detail (``volviz.render.lod_volume``), else through the
    wavelet decoder
    (damaged bricks are filled from the coarser level and reported as warnings, never silently)."""
    if path.suffix.lower() == ".vvz":
        if options.get("lod"):           # level of detail: blocks decoded on demand for each view
            from volviz.regular.lod import LodTree   # heavy (Numba kernels): only for a compressed volume

            return LodTree(path, cache_bytes=json_int(options.get("cache_mb", 256)) << 20)
        from volviz.regular.codec import decompress   # heavy (Numba kernels): only for a compressed volume

        return decompress(path, progress=progress)
    reader_options: Mapping[str, Any] = options   # volviz.io.read's keyword options: each reader checks its own
    return read(path, **reader_options)


def component_dataset(comp: Component, datasets: dict[str, LoadedDataset]) -> LoadedDataset:
    """The dataset a component shows: generated for the demo, else the loaded dataset it names."""
    if comp.type == "demo":
        key = f"demo:{int(comp.settings.get('cells_per_edge', 20))}"
        if key not in datasets:
            datasets[key] = demo_tet_mesh(int(comp.settings.get("cells_per_edge", 20)))
        return datasets[key]
    if comp.dataset is None:
        raise SceneError(f"component {comp.id!r} ({comp.type}) names no dataset")
    if comp.type in NATURE_TYPES:
        return datasets[comp.dataset]
    try:
        return shown_array(datasets[comp.dataset], comp.settings.get("array"))
    except ValueError as exc:
        raise SceneError(f"component {comp.id!r}: {exc}") from None


def shown_array(dataset: LoadedDataset, spec: Optional[str]) -> LoadedDataset:
    """``dataset`` showing the array ``spec`` (None: its default array; ``volviz.model.arrays``), made once per spec
    and kept while the dataset lives, so the tetrahedralisation and topology cached on the view are made once too.
    The views are kept here by the dataset's identity (``_VIEWS``), not on the dataset, and dropped with it."""
    if isinstance(dataset, Image2D) or is_lod(dataset):
        return dataset
    views = _views_of(dataset)
    if views is None:   # an object without weak references: nothing to drop the views with, so none kept
        return select_array(dataset, spec)
    if spec not in views:
        view = select_array(_detached(dataset), spec)
        views.setdefault(spec, None if view is dataset else view)   # two threads asking at once get one view
    kept = views[spec]
    return dataset if kept is None else kept


#: id(dataset) -> array spec -> the view showing it (None: the dataset itself), by identity since the model's datasets
#: are dataclasses compared by value (unhashable: no WeakKeyDictionary); an entry is removed when its dataset is
#: collected (``weakref.finalize``), before its id can name another object. No view refers to its dataset
#: (``_detached``), so the entry never keeps the dataset alive.
_VIEWS: dict[int, dict[Optional[str], Any]] = {}


def _views_of(dataset: LoadedDataset) -> Optional[dict[Optional[str], Any]]:
    """The views kept for ``dataset`` (None when it takes no weak reference)."""
    fresh: dict[Optional[str], Any] = {}
    views = _VIEWS.setdefault(id(dataset), fresh)
    if views is fresh:
        try:
            weakref.finalize(dataset, _VIEWS.pop, id(dataset), None)
        except TypeError:
            del _VIEWS[id(dataset)]
            return None
    return views


def _detached(dataset: Union[Dataset, TimeSeries]) -> Union[Dataset, TimeSeries]:
    """What the views of ``dataset`` are made from: the dataset, or for a time series a twin sharing its frame list
    and loader (frames loaded through a view are kept in the series as before), since a series' view loads its
    frames through what it was made from, and a view kept in ``_VIEWS`` must not keep its dataset alive."""
    if isinstance(dataset, TimeSeries):
        return TimeSeries(dataset.times, dataset.frames, dataset.loader, dataset.source)
    return dataset


def dataset_traits(dataset: LoadedDataset) -> DatasetTraits:
    """What a loaded dataset (as ``read_any`` gives it) is, for the settings that apply to some datasets only
    (``volviz.model.applicability``): a time series, a compressed volume drawn at a level of detail."""
    return DatasetTraits(time_series=isinstance(dataset, TimeSeries), lod_volume=is_lod(dataset))


def drawn_as(dataset: LoadedDataset) -> str:
    """How a volume component draws a loaded dataset: ``"points"`` (a mesh of vertices only, e.g. a point table),
    ``"surface"`` (surface cells, a flat grid, no field or a constant one: ``volviz.model.representation``) or
    ``"volume"``."""
    return "volume" if is_lod(dataset) else representation(dataset).kind
