"""Build what a session (or a single data file) shows into any PyVista plotter: offscreen for export, or the app's.

Only the components a session lists are loaded and added (DESIGN.md "Model only what a scene needs"); datasets shared
by several components are read once.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Optional

from volviz.jobs import ProgressCallback, report
from volviz.session import Component, DatasetRef, Session, resolve_path


class SceneError(Exception):
    """A session that cannot be shown: names the component and the problem."""


def data_session(path: str | os.PathLike) -> Session:
    """A one-dataset session that shows ``path`` with its default visual (what opening a data file does)."""
    ref = DatasetRef(id="data", path=str(Path(path).resolve()))
    return Session(datasets=[ref], components=[Component(id="data", type="volume", dataset="data")])


def demo_session() -> Session:
    """The built-in procedural demo (generated at start-up, no files)."""
    return Session(components=[Component(id="demo", type="demo", settings={"cells_per_edge": 20})])


def load_datasets(session: Session, session_file: Optional[str | os.PathLike],
                  progress: Optional[ProgressCallback] = None) -> dict[str, Any]:
    """Read every dataset that a visible component uses, once each, with progress."""
    used = {c.dataset for c in session.components if c.visible and c.dataset is not None}
    refs = [ref for ref in session.datasets if ref.id in used]
    loaded: dict[str, Any] = {}
    for i, ref in enumerate(refs):
        report(progress, i / max(len(refs), 1), f"reading {Path(ref.path).name}")
        path = resolve_path(session_file, ref.path) if session_file else Path(ref.path)
        from volviz.io import read

        loaded[ref.id] = read(path, **ref.options)
    report(progress, 1.0, "datasets read")
    return loaded


def build_scene(plotter: Any, session: Session, datasets: dict[str, Any]) -> dict[str, Any]:
    """Add every visible component to ``plotter``; returns the VTK prop of each component by id."""
    from volviz.render.vtk_scene import add_dataset, apply_camera

    props: dict[str, Any] = {}
    for comp in session.components:
        if not comp.visible:
            continue
        if comp.type == "demo":
            from volviz.model.demo import demo_tet_mesh

            dataset = demo_tet_mesh(int(comp.settings.get("cells_per_edge", 20)))
        elif comp.dataset is None:
            raise SceneError(f"component {comp.id!r} ({comp.type}) names no dataset")
        else:
            dataset = datasets[comp.dataset]
        style = None
        if comp.transfer_function is not None:
            style = style_from_transfer_function(session.transfer_functions[comp.transfer_function], dataset)
        props[comp.id] = add_dataset(plotter, dataset, style=style, opacity=comp.opacity, name=comp.id)
    plotter.set_background(session.render.background)
    apply_camera(plotter, session.camera)
    return props


def style_from_transfer_function(tf_dict: dict[str, Any], dataset: Any) -> Any:
    """VTK colour/opacity points for a session transfer function (VTK convention: ρ = opacity / unit distance)."""
    from volviz.optics import TransferFunction
    from volviz.render.vtk_scene import VolumeStyle

    tf = TransferFunction.from_dict(tf_dict)
    unit = 1.0
    ctf, otf = tf.to_vtk(unit)
    colors = []
    for i in range(ctf.GetSize()):
        node = [0.0] * 6
        ctf.GetNodeValue(i, node)
        colors.append((node[0], node[1], node[2], node[3]))
    opacities = []
    for i in range(otf.GetSize()):
        node = [0.0] * 4
        otf.GetNodeValue(i, node)
        opacities.append((node[0], node[1]))
    return VolumeStyle(colors, opacities, unit)
