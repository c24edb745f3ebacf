"""What frames the data on screen: a scalar bar (the color legend of the shown array with its name and range),
the orientation axes and the outline box of the data. Each is a render option of the session (``scalar_bar``,
``axes``, ``outline``; on unless set to false), so it is saved with the session and can be switched off."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Mapping, Optional, Sequence

import numpy as np

from volviz.model.arrays import MAGNITUDE, default_array, is_appearance_array, parse_array_spec
from volviz.model.settings import ScalarBarStyle, array_key, validated
from volviz.optics.log_scale import log_mapped, log_ticks
from volviz.render.framing import scene_bounds
from volviz.render.vtk_scene import is_surface
from volviz.render.vtk_tf import tf_to_vtk
from volviz.scene.datasets import component_dataset
from volviz.scene.drawn_tf import log_floor, uses_log_scale
from volviz.scene.errors import SceneError
from volviz.scene.lod import is_lod
from volviz.session import Component, Session

if TYPE_CHECKING:   # type-only: PyVista's mesh and plotter classes, imported where an outline is made; VTK's prop
    import pyvista as pv

    from volviz.render.vtk_facade import vtkProp
    from volviz.scene.datasets import LoadedDataset

DECORATIONS = ("scalar_bar", "axes", "outline")
OUTLINE_NAME = "volviz-outline"
SCALAR_BAR_NAME = "volviz-scalar-bar"
SCALAR_BAR_TITLE_NAME = "volviz-scalar-bar-title"


def decoration_enabled(session: Session, name: str) -> bool:
    """Whether the decoration ``name`` (one of ``DECORATIONS``) is on in the session's render options."""
    return bool(session.render.options.get(name, True))


LEGEND_MARGIN = 0.2        # the share of the viewport's width at its right that framing keeps for the scalar bar


def legend_margin(session: Session, datasets: Optional[dict[str, LoadedDataset]] = None) -> float:
    """How much of the viewport's width, at its right, the scalar bar takes (0 when none is shown; with the loaded
    ``datasets``, also when the component it would explain colors by no array)."""
    comp = _legend_component(session) if decoration_enabled(session, "scalar_bar") else None
    shown = comp is not None and (datasets is None or _shows_array(comp, datasets))
    return LEGEND_MARGIN if shown else 0.0


def _legend_component(session: Session) -> Optional[Any]:
    """The first visible component with a transfer function: the one the scalar bar explains."""
    return next((c for c in session.components
                 if c.visible and c.transfer_function is not None
                 and c.transfer_function in session.transfer_functions),
                None)


def _contrast(background: Any) -> tuple[float, float, float]:
    """Black or white, whichever reads better on ``background``."""
    luminance = float(np.dot(np.asarray(background, dtype=np.float64)[:3], (0.299, 0.587, 0.114)))
    return (0.1, 0.1, 0.1) if luminance > 0.5 else (0.92, 0.92, 0.92)


def apply_decorations(plotter: pv.BasePlotter, session: Session, props: Mapping[str, object],
                      datasets: dict[str, LoadedDataset]) -> None:
    """Show or hide the scalar bar, orientation axes and outline box of the scene in ``plotter`` as the session's
    render options say (``props``: the components' props, whose bounds the outline draws; ``datasets``: the loaded
    datasets, whose shown array names the scalar bar). Safe to call again after any change: it replaces what it
    added before."""
    update_outline(plotter, session, props)
    color = _contrast(session.render.background)
    axes = getattr(plotter.renderer, "axes_widget", None)
    if decoration_enabled(session, "axes"):
        if axes is None:   # 1-pixel shafts: pyvista's 2-pixel lines were drawn a pixel apart on screen and in
            # ``volviz render`` (VTK's wide lines take the driver's or its own path by context; issue #28)
            plotter.add_axes(color=color, interactive=False, line_width=1)  # type: ignore[call-arg]  # _Wrapped: no self
        else:
            plotter.renderer.show_axes()
    elif axes is not None:
        plotter.renderer.hide_axes()
    update_legend(plotter, session, datasets)


def update_outline(plotter: pv.BasePlotter, session: Session, props: Mapping[str, object]) -> None:
    """Redraw only the outline box around ``props`` (data that moved: the scalar bar and axes stay as they are)."""
    plotter.remove_actor(OUTLINE_NAME, render=False)  # type: ignore[arg-type]  # pyvista's _Wrapped hides self
    if decoration_enabled(session, "outline"):
        data = {k: p for k, p in props.items() if k != "nature"}   # a landscape needs no box around it
        bounds = scene_bounds(data)
        if bounds is not None:
            actor = plotter.add_mesh(outline_box(bounds), color=_contrast(session.render.background),
                                     name=OUTLINE_NAME, pickable=False, reset_camera=False, render=False,
                                     line_width=1)
            _in_front_of_coincident(actor)


def outline_box(bounds: Sequence[float]) -> pv.PolyData:
    """The 12 edges of the box ``bounds`` (xmin, xmax, ymin, ymax, zmin, zmax) as a float64 ``pyvista.PolyData``:
    ``pv.Box(...).outline()`` made float32 points, up to 0.5 m off at UTM coordinates (y = 7e6)."""
    # heavy: PyVista (about 180 modules), loaded only when an outline is drawn
    import pyvista as pv

    b = np.asarray(bounds, dtype=np.float64).reshape(3, 2)
    corners = np.array([[b[0, i], b[1, j], b[2, k]] for k in (0, 1) for j in (0, 1) for i in (0, 1)])
    edges = [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)]
    return pv.PolyData(corners, lines=np.array([[2, a, c] for a, c in edges]).ravel())


OUTLINE_DEPTH_OFFSET = 4e-6   # normalised device depth the outline is drawn nearer by (~34 steps of a 24-bit buffer)


def _in_front_of_coincident(actor: Any) -> None:
    """Draw the outline's lines a hair nearer than a surface they lie on (a picture shown flat is its own box, its
    border rows under three of the four sides): with equal depths the picture's pixels won and those sides vanished
    (issue #28). VTK's coincident-topology offsets are one global switch for every mapper, so the outline's own
    vertex shader moves it instead; in eye space that is ~0.2 % of the depth at 1000 times the near distance."""
    actor.GetShaderProperty().AddVertexShaderReplacement(
        "//VTK::PositionVC::Impl", True,
        f"//VTK::PositionVC::Impl\n  gl_Position.z -= {OUTLINE_DEPTH_OFFSET!r} * gl_Position.w;\n", False)


def update_legend(plotter: pv.BasePlotter, session: Session, datasets: dict[str, LoadedDataset]) -> None:
    """Redraw only the scalar bar (after a transfer-function edit: the outline and axes stay as they are)."""
    _remove_scalar_bar(plotter)
    comp = _legend_component(session) if decoration_enabled(session, "scalar_bar") else None
    if comp is not None and _shows_array(comp, datasets):
        _add_scalar_bar(plotter, session, comp, datasets, _contrast(session.render.background))


def label_values(lo: float, hi: float, count: int = 5) -> np.ndarray:
    """The scalar bar's ``count`` evenly spaced label values from ``lo`` to ``hi``; a value within a thousandth of
    the range of zero is written as 0 (below the labels' 3 significant digits, and a thousandth of the bar's height
    from where it is drawn): the middle of a nearly symmetric range (-6.98328 .. 6.98321) is -3.3e-05, which VTK's
    own labels print in full."""
    values = np.linspace(float(lo), float(hi), int(count))
    values[np.abs(values) < 1e-3 * abs(float(hi) - float(lo))] = 0.0
    return values


def label_format(lo: float, hi: float, count: int = 5) -> str:
    """The printf format of the scalar bar's labels (``label_values``): fixed-point with the decimals that show the
    label step to 2 significant digits ("-1000", "0.25"), or scientific notation with the digits that tell the labels
    apart ("2.50e-07") when that is shorter. VTK's "%-#6.3g" printed "1.00e+03" for 1000, which ran off the right
    edge of exports narrower than ~350 pixels, and "1.16e+03" for 1162."""
    step = abs(float(hi) - float(lo)) / max(int(count) - 1, 1)
    if not (np.isfinite(step) and step > 0):
        return "%.3g"
    values = label_values(lo, hi, count)
    decimals = max(0, 1 - int(np.floor(np.log10(step))))
    biggest = float(np.abs(values).max())
    digits = min(max(2 + int(np.ceil(np.log10(max(biggest / step, 1.0)))), 3), 10)
    candidates = [f"%.{decimals}f", f"%.{digits - 1}e"]
    return min(candidates, key=lambda fmt: max(len(fmt % v) for v in values))


def scalar_bar_style(session: Session) -> ScalarBarStyle:
    """The session's edits of the scalar bar (title, range, number format; each unset follows the data)."""
    return validated(ScalarBarStyle, session.render.options.get("scalar_bar_style") or {},
                     "render.options.scalar_bar_style")


def _bar_scale(session: Session, comp: Any, datasets: dict[str, Any]) -> tuple[Any, np.ndarray, str, bool]:
    """The scalar bar's color function, label values, label format and whether it is logarithmic: the component's
    transfer function (through log10 with ``log_scale``: log ticks from the smallest positive value) over the edited
    range, else over the function's own."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    style = scalar_bar_style(session)
    tf = session.transfer_functions[comp.transfer_function]
    lo, hi = style.range or tf.range
    log = False
    if uses_log_scale(comp):
        try:
            floor = log_floor(tf, component_dataset(comp, datasets))
        except (SceneError, KeyError):
            floor = log_floor(tf, None)
        tf = log_mapped(tf, floor)
        lo, log = max(lo, floor), hi > max(lo, floor) > 0
    if not log and style.range is None:
        ctf, _ = tf_to_vtk(tf, 1.0)
    else:   # sampled: a range of its own, or a log scale (VTK interpolates a log table between its nodes in log10)
        values = np.geomspace(lo, hi, 256) if log else np.linspace(lo, hi, 256)
        colors, _ = tf.evaluate(np.clip(values, *tf.range))
        ctf = vtk.vtkColorTransferFunction()
        ctf.SetColorSpaceToRGB()
        for v, (r, g, b) in zip(values, colors):
            ctf.AddRGBPoint(float(v), float(r), float(g), float(b))
        if log:
            ctf.SetScaleToLog10()
    ctf.ClampingOn()
    labels = log_ticks(lo, hi) if log else label_values(lo, hi)
    return ctf, labels, style.format or ("%.3g" if log else label_format(lo, hi)), log


BAR_LEFT = 0.84             # the scalar bar's left edge (normalized viewport), its color strip's too
TITLE_TOP = (BAR_LEFT, 0.86)   # the title's place (normalized viewport, bottom left of the text): over the bar
TITLE_RIGHT = 0.98          # the furthest right its end may reach (normalized viewport)


def _add_scalar_bar(plotter: Any, session: Session, comp: Any, datasets: dict[str, Any],
                    color: tuple[float, float, float]) -> None:
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import numpy_to_vtk, vtk

    ctf, labels, fmt, log = _bar_scale(session, comp, datasets)
    title = scalar_bar_style(session).title
    if title is None:
        title = _array_title(comp, datasets) + (" (log)" if log else "")
    bar = vtk.vtkScalarBarActor()
    bar.SetLookupTable(ctf)
    bar.SetCustomLabels(numpy_to_vtk(labels, deep=True))
    bar.UseCustomLabelsOn()
    bar.SetLabelFormat(fmt)
    bar.SetOrientationToVertical()          # at the right edge, as ParaView places it
    bar.SetPosition(BAR_LEFT, 0.12)
    bar.SetWidth(0.12)
    bar.SetHeight(0.72)
    bar.SetMaximumWidthInPixels(110)
    bar.SetBarRatio(0.25)
    bar.UnconstrainedFontSizeOn()
    label = bar.GetLabelTextProperty()
    # the title is a text of its own above the bar, placed at each render (``_place_title``)
    heading = vtk.vtkTextActor()
    heading.SetInput(str(title))
    heading.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
    heading.SetPosition(TITLE_TOP[0], TITLE_TOP[1])
    heading_text = heading.GetTextProperty()
    heading_text.SetJustificationToLeft()
    heading_text.SetVerticalJustificationToBottom()
    for text in (heading_text, label):
        text.SetColor(*color)
        text.ShadowOff()
        text.ItalicOff()
        text.BoldOff()
        text.SetFontSize(12)
    plotter.add_actor(bar, name=SCALAR_BAR_NAME, reset_camera=False, render=False, pickable=False)
    plotter.add_actor(heading, name=SCALAR_BAR_TITLE_NAME, reset_camera=False, render=False, pickable=False)
    renderer = plotter.renderer
    tag = renderer.AddObserver("StartEvent", lambda *_: _place_title(heading, renderer))
    heading.volviz_observer = (renderer, tag)   # removed with the title (``_remove_scalar_bar``)


def _place_title(heading: Any, renderer: Any) -> None:
    """The scalar bar's title left-aligned with the bar, as ParaView draws it over its bar; a title too long for
    the room from there to ``TITLE_RIGHT`` is moved left until its end is there (it runs left, not off the window).
    Done at each render: the bar's pixel place and the title's pixel width depend on the window's size. Before, the
    title was right-aligned at ``TITLE_RIGHT``, 60-100 pixels right of the bar (issue #28)."""
    width = renderer.GetSize()[0]
    if width <= 0:
        return
    box = [0.0] * 4
    heading.GetBoundingBox(renderer, box)
    room = TITLE_RIGHT - (box[1] - box[0]) / width
    heading.SetPosition(max(0.0, min(TITLE_TOP[0], room)), TITLE_TOP[1])


def _shows_array(comp: Component, datasets: dict[str, LoadedDataset]) -> bool:
    """Whether the component colors by an array through its transfer function (its setting, else its dataset's
    default): a surface of geometry alone (an STL, a PLY of normals) is drawn in a plain color, and one showing an
    appearance array (``red`` of a coloured point cloud, ``volviz.model.arrays.is_appearance_array``) in its own
    vertex colors (``vtk_scene.surface_input``): no scale to explain either way."""
    if comp.type != "volume":
        return True

    dataset = datasets.get(comp.dataset) if comp.dataset is not None else None
    if dataset is None or is_lod(dataset) or not is_surface(dataset):   # (a LOD volume is drawn as a volume)
        return True
    spec = comp.settings.get(array_key(comp.type))
    if not spec:
        try:
            spec = default_array(dataset)
        except (TypeError, ValueError, AttributeError):
            return True
    return spec is not None and not is_appearance_array(parse_array_spec(str(spec)).name)


def _array_title(comp: Any, datasets: dict[str, Any]) -> str:
    """The name of the array a component shows (its ``array`` setting, else its dataset's default array)."""
    shown = comp.settings.get(array_key(comp.type))
    if shown:
        return _readable(str(shown))

    try:
        shown = component_dataset(comp, datasets)
    except (SceneError, KeyError):
        return str(comp.id)
    if hasattr(shown, "frame"):
        shown = shown.frame(0)
    return _readable(str(getattr(shown, "active", None) or getattr(shown, "name", None) or comp.id))


def _readable(spec: str) -> str:
    """An array spec as a legend title: ``V:magnitude`` -> ``V (magnitude)``, ``V:1`` -> ``V[1]``."""
    parsed = parse_array_spec(spec)
    if parsed.component == MAGNITUDE:
        return f"{parsed.name} (magnitude)"
    return parsed.name if parsed.component is None else f"{parsed.name}[{parsed.component}]"


def _remove_scalar_bar(plotter: Any) -> None:
    heading = plotter.renderer.actors.get(SCALAR_BAR_TITLE_NAME)
    if heading is not None and hasattr(heading, "volviz_observer"):
        owner, tag = heading.volviz_observer
        owner.RemoveObserver(tag)
    plotter.remove_actor(SCALAR_BAR_NAME, render=False)
    plotter.remove_actor(SCALAR_BAR_TITLE_NAME, render=False)


def scalar_bar_actor(plotter: pv.BasePlotter) -> Optional[vtkProp]:
    """The scalar bar ``apply_decorations`` added (None when off or when nothing has a transfer function)."""
    return plotter.renderer.actors.get(SCALAR_BAR_NAME)


def scalar_bar_title(plotter: pv.BasePlotter) -> Optional[str]:
    """The scalar bar's title (the shown array's name), None without a scalar bar."""
    heading = plotter.renderer.actors.get(SCALAR_BAR_TITLE_NAME)
    return None if heading is None else str(heading.GetInput())


def scalar_bar_hit(plotter: pv.BasePlotter, x: float, y: float) -> bool:
    """Whether display pixel (x, y) (VTK's: rows from the bottom) is on the scalar bar or its title."""
    renderer = plotter.renderer
    for name in (SCALAR_BAR_NAME, SCALAR_BAR_TITLE_NAME):
        actor = renderer.actors.get(name)
        if actor is None:
            continue
        box = [0.0] * 4
        if name == SCALAR_BAR_NAME:
            lo = actor.GetPositionCoordinate().GetComputedDisplayValue(renderer)
            hi = actor.GetPosition2Coordinate().GetComputedDisplayValue(renderer)
            box = [lo[0], hi[0], lo[1], hi[1]]
        else:
            bounds = [0.0] * 4
            actor.GetBoundingBox(renderer, bounds)
            box = bounds
        if box[0] <= x <= box[1] and box[2] <= y <= box[3]:
            return True
    return False
