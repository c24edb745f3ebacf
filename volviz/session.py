"""Session files: versioned, validated JSON; atomic save (docs/design.md "Sessions").

A session is ``{"format": "volviz-session", "version": N, ...}`` with datasets (paths relative to the session file),
scene components and their settings, transfer functions, camera, camera paths and bookmarks, render settings and the
window layout. Loading validates every field and names the offending one (``components[1].opacity: ...``); a newer
version is refused; older versions are migrated step by step through ``MIGRATIONS``. Nothing read is executed or
unpickled: the file is parsed with ``json`` and every value is checked against the schema below.

The transfer functions and the clipping are held as typed, immutable models (``volviz.optics.TransferFunction``,
``volviz.model.clip.ClipSettings``), made from the JSON when a document is read (``session_from_dict``) and written
back only when it is saved (``session_to_dict``), so every reader takes the model (issue #31). A file volviz wrote
saves byte for byte as it was read; a hand-written one is saved in the models' form: whole numbers of a transfer
function as floats (``1`` -> ``1.0``), its ``format``, ``version`` and ``name`` (``""``) written out, and a clipping
normal as its unit vector (``[0, 0, 2]`` -> ``[0.0, 0.0, 1.0]``: the same half-space).

Untrusted files cannot make loading slow, deep or large: the file must be a regular file (a FIFO or device is refused
before it is opened, so it can never block the reader) of at most ``MAX_SESSION_BYTES``; before parsing, a scan of
the bytes bounds the nesting depth (``MAX_DEPTH``) and the number of values (``MAX_VALUES``); while parsing, numbers
longer than ``MAX_NUMBER_CHARS`` are refused; after parsing, every string, key, list and object is held to
``MAX_STRING_CHARS``, ``MAX_KEY_CHARS`` and ``MAX_ITEMS``. Messages name the file and the field and describe bad
values instead of quoting them (only short identifiers are quoted).
"""
from __future__ import annotations

import copy
import errno
import json
import math
import os
import re
import stat
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, get_args

from volviz.io._checks import path_kind
from volviz.io.atomic import OutputPathError, atomic_write_bytes
from volviz.io.errors import ReadError
from volviz.io.jsonbounds import nesting_depth, outside_strings
from volviz.io.option_check import OptionProblem, check_reader_options
from volviz.io.registry import reader_specs
from volviz.io.series import expand_pattern
from volviz.model.clip import BoxCrop, ClipPlane, ClipSettings
from volviz.model.events import ChangeNotifier, SceneChange
from volviz.model.settings import Backend, IsoOverlayMode, SettingsError, validate_render_options, validate_settings

if TYPE_CHECKING:
    from volviz.optics.transfer_function import TransferFunction

FORMAT = "volviz-session"
VERSION = 1
MAX_SESSION_BYTES = 16 * 1024 * 1024  # ample for MAX_VALUES values
MAX_DEPTH = 64               # nesting of lists and objects
MAX_VALUES = 1_000_000       # values (numbers, strings, lists, objects) in the whole document
MAX_ITEMS = 65_536           # items of one list or members of one object (transfer-function points, camera keys)
MAX_NUMBER_CHARS = 100       # characters of one number (Python would parse a 5000-digit integer, slowly)
MAX_STRING_CHARS = 65_536    # characters of one string value
MAX_KEY_CHARS = 128          # characters of one object key (keys appear in field paths of error messages)
MAX_OPTION_ITEMS = 16        # items of a list-valued dataset option (dims, spacing, ...)

COMPONENT_TYPES = ("volume", "mesh", "isosurface", "terrain", "fog", "clouds", "sky", "demo", "slices")
RENDER_METHODS = ("auto", "pt", "reference", "vtk")
RENDER_BACKENDS = get_args(Backend)   # render option "backend" (volviz.render.backend)
ISO_MODES: tuple[str, ...] = get_args(IsoOverlayMode)  # render option "iso_mode": "vtk" or a libMini note §4 mode


class SessionError(Exception):
    """A session file that cannot be loaded or saved; names the file and, for bad content, the field path."""

    def __init__(self, path: str | os.PathLike | None, problem: str, field: str | None = None):
        self.path = None if path is None else str(path)
        self.field = field
        self.problem = problem
        where = f"{self.path}: " if self.path else ""
        what = f"{field}: " if field else ""
        super().__init__(f"{where}{what}{problem}")


@dataclass
class DatasetRef:
    id: str
    path: str
    options: dict[str, Any] = field(default_factory=dict)


@dataclass
class Component:
    id: str
    type: str
    dataset: str | None = None
    visible: bool = True
    opacity: float = 1.0
    transfer_function: str | None = None
    settings: dict[str, Any] = field(default_factory=dict)


@dataclass
class CameraState:
    position: tuple[float, float, float] = (1.0, 1.0, 1.0)
    focal_point: tuple[float, float, float] = (0.0, 0.0, 0.0)
    view_up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    view_angle: float = 30.0
    parallel: bool = False
    parallel_scale: float = 1.0


@dataclass
class CameraKey:
    time: float
    camera: CameraState


@dataclass
class RenderSettings:
    method: str = "auto"
    size: tuple[int, int] = (1024, 768)
    background: tuple[float, float, float] = (0.1, 0.1, 0.12)
    options: dict[str, Any] = field(default_factory=dict)


@dataclass
class Session:
    datasets: list[DatasetRef] = field(default_factory=list)
    components: list[Component] = field(default_factory=list)
    transfer_functions: dict[str, TransferFunction] = field(default_factory=dict)
    camera: CameraState | None = None
    camera_paths: dict[str, list[CameraKey]] = field(default_factory=dict)
    bookmarks: dict[str, CameraState] = field(default_factory=dict)
    render: RenderSettings = field(default_factory=RenderSettings)
    layout: dict[str, Any] = field(default_factory=dict)
    clip: ClipSettings = field(default_factory=ClipSettings)
    #: announces each edit made through the methods below (``volviz.model.events``); not part of the document
    changes: ChangeNotifier = field(default_factory=ChangeNotifier, repr=False, compare=False)

    def dataset(self, dataset_id: str) -> DatasetRef:
        for ref in self.datasets:
            if ref.id == dataset_id:
                return ref
        raise KeyError(dataset_id)

    def component(self, comp_id: str) -> Component:
        for comp in self.components:
            if comp.id == comp_id:
                return comp
        raise KeyError(comp_id)

    # -- edits (issue #31): each changes the session, then announces it on ``changes``; whoever made it (a dock, an
    # undo step, a script), the views follow through their subscription (``volviz.render.controller``)
    def set_transfer_function(self, comp_id: str, tf: TransferFunction, preview: bool = False) -> None:
        """Give component ``comp_id`` the transfer function ``tf`` (stored under the component's TF name, else its
        id); ``preview``: an edit under way (a point being dragged)."""
        comp = self.component(comp_id)
        name = comp.transfer_function or comp.id
        self.transfer_functions[name] = tf
        comp.transfer_function = name
        self.changes.notify(SceneChange("transfer_function", comp_id, preview))

    def transfer_function(self, comp_id: str) -> TransferFunction | None:
        """Component ``comp_id``'s transfer function (None without one)."""
        name = self.component(comp_id).transfer_function
        return None if name is None else self.transfer_functions[name]

    def set_visible(self, comp_id: str, visible: bool) -> None:
        self.component(comp_id).visible = bool(visible)
        self.changes.notify(SceneChange("visible", comp_id))

    def set_opacity(self, comp_id: str, opacity: float) -> None:
        """Set a component's opacity, clamped to [0, 1]."""
        self.component(comp_id).opacity = float(min(max(opacity, 0.0), 1.0))
        self.changes.notify(SceneChange("opacity", comp_id))

    def set_clip(self, clip: dict[str, Any] | ClipSettings) -> None:
        """New scene-wide clipping (``ClipSettings``, or its JSON as the clipping dock emits it, read here once);
        raises ``ValueError`` naming what is wrong with it, changing nothing."""
        self.clip = clip if isinstance(clip, ClipSettings) else ClipSettings.from_dict(clip)
        self.changes.notify(SceneChange("clip"))

    def set_iso_mode(self, mode: str) -> None:
        """The isosurfaces' transparency mode (render option ``iso_mode``, one of ``ISO_MODES``); announced only when
        it changes."""
        if mode not in ISO_MODES:
            raise ValueError(f"unknown isosurface mode {mode!r}; choose from {ISO_MODES}")
        changed = mode != self.render.options.get("iso_mode", "vtk")
        if mode != "vtk" or "iso_mode" in self.render.options:
            self.render.options["iso_mode"] = mode
        if changed:
            self.changes.notify(SceneChange("iso_mode"))


# --------------------------------------------------------------------------------------------------------- validation
class _Reader:
    """Walks a parsed JSON document, checking types and naming the field path on the first problem."""

    def __init__(self, source: str | None):
        self.source = source

    def fail(self, where: str, problem: str) -> SessionError:
        return SessionError(self.source, problem, where)

    def obj(self, value: Any, where: str) -> dict[str, Any]:
        if not isinstance(value, dict):
            raise self.fail(where, f"expected an object, got {_kind(value)}")
        return value

    def lst(self, value: Any, where: str) -> list[Any]:
        if not isinstance(value, list):
            raise self.fail(where, f"expected a list, got {_kind(value)}")
        return value

    def string(self, value: Any, where: str, choices: tuple[str, ...] | None = None) -> str:
        if not isinstance(value, str):
            raise self.fail(where, f"expected a string, got {_kind(value)}")
        if choices is not None and value not in choices:
            raise self.fail(where, f"expected one of {', '.join(choices)}, got {_quote(value)}")
        return value

    def boolean(self, value: Any, where: str) -> bool:
        if not isinstance(value, bool):
            raise self.fail(where, f"expected true or false, got {_kind(value)}")
        return value

    def number(self, value: Any, where: str, lo: float = -math.inf, hi: float = math.inf) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise self.fail(where, f"expected a finite number, got {_kind(value)}")
        if not lo <= value <= hi:
            raise self.fail(where, f"expected a number in [{lo}, {hi}], got {value}")
        return float(value)

    def vector(self, value: Any, where: str, n: int = 3) -> tuple[float, ...]:
        items = self.lst(value, where)
        if len(items) != n:
            raise self.fail(where, f"expected {n} numbers, got {len(items)}")
        return tuple(self.number(v, f"{where}[{i}]") for i, v in enumerate(items))

    def json_value(self, value: Any, where: str) -> Any:
        """Free-form settings: plain JSON only (objects, lists, strings, finite numbers, booleans, null)."""
        if isinstance(value, dict):
            return {self.string(k, where): self.json_value(v, f"{where}.{k}") for k, v in value.items()}
        if isinstance(value, list):
            return [self.json_value(v, f"{where}[{i}]") for i, v in enumerate(value)]
        if isinstance(value, float) and not math.isfinite(value):
            raise self.fail(where, "NaN and Infinity are not allowed")
        if value is None or isinstance(value, (str, bool, int, float)):
            return value
        raise self.fail(where, f"unsupported value {_kind(value)}")

    def known_keys(self, value: dict[str, Any], where: str, keys: set[str]) -> None:
        unknown = sorted(set(value) - keys)
        if unknown:
            raise self.fail(f"{where}.{unknown[0]}" if where else unknown[0], "unknown field")

    def camera(self, value: Any, where: str) -> CameraState:
        d = self.obj(value, where)
        self.known_keys(d, where, {"position", "focal_point", "view_up", "view_angle", "parallel", "parallel_scale"})
        cam = CameraState(
            position=self.vector(d.get("position", [1, 1, 1]), f"{where}.position"),  # type: ignore[arg-type]
            focal_point=self.vector(d.get("focal_point", [0, 0, 0]), f"{where}.focal_point"),  # type: ignore[arg-type]
            view_up=self.vector(d.get("view_up", [0, 0, 1]), f"{where}.view_up"),  # type: ignore[arg-type]
            view_angle=self.number(d.get("view_angle", 30.0), f"{where}.view_angle", 1e-3, 179.0),
            parallel=self.boolean(d.get("parallel", False), f"{where}.parallel"),
            parallel_scale=self.number(d.get("parallel_scale", 1.0), f"{where}.parallel_scale", 1e-12),
        )
        if all(a == b for a, b in zip(cam.position, cam.focal_point)):
            raise self.fail(where, "position and focal_point coincide")
        if all(v == 0 for v in cam.view_up):
            raise self.fail(f"{where}.view_up", "must not be the zero vector")
        return cam


def _kind(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return f"the string {_quote(value)}" if _SAFE_TEXT.match(value) else _quote(value)
    kinds: dict[type, str] = {dict: "an object", list: "a list"}
    return kinds.get(type(value), type(value).__name__)


_SAFE_TEXT = re.compile(r"[A-Za-z0-9_.:+/ -]{1,40}\Z")


def _quote(text: str) -> str:
    """A string from the file for a message: a short identifier is quoted (it is what the user wrote and needs to
    find); anything else is described, never echoed."""
    if _SAFE_TEXT.match(text):
        return repr(text)
    return "an empty string" if not text else f"a string of {len(text)} characters"


TF_FIELDS = {"format", "version", "name", "scalars", "colors", "extinction"}  # TransferFunction.to_dict's


def _read_transfer_function(reader: _Reader, value: Any, where: str) -> TransferFunction:
    """A transfer function of the document as the typed model (``TransferFunction.from_dict``, Roettger §7.1)."""
    # here, not at the top: volviz.optics loads numba (+0.1 s), which a session without transfer functions skips
    from volviz.optics.transfer_function import TransferFunction

    d = reader.json_value(reader.obj(value, where), where)
    reader.known_keys(d, where, TF_FIELDS)
    try:
        return TransferFunction.from_dict(d)
    except (ValueError, TypeError, KeyError) as exc:
        raise reader.fail(where, f"invalid transfer function: {exc}") from None


def session_from_dict(doc: Any, source: str | os.PathLike | None = None) -> Session:
    """Validate a parsed session document (already migrated to ``VERSION``) and build a ``Session``."""
    r = _Reader(None if source is None else str(source))
    d = r.obj(doc, "(document)")
    r.known_keys(d, "", {"format", "version", "datasets", "components", "transfer_functions", "camera",
                         "camera_paths", "bookmarks", "render", "layout", "clip"})
    session = Session()

    ids: set[str] = set()
    for i, item in enumerate(r.lst(d.get("datasets", []), "datasets")):
        where = f"datasets[{i}]"
        o = r.obj(item, where)
        r.known_keys(o, where, {"id", "path", "options"})
        ref = DatasetRef(id=r.string(o.get("id"), f"{where}.id"), path=r.string(o.get("path"), f"{where}.path"),
                         options=_read_options(r, o.get("options", {}), f"{where}.options"))
        if not ref.path:
            raise r.fail(f"{where}.path", "must not be empty")
        if "\0" in ref.path or len(ref.path) > 4096:
            raise r.fail(f"{where}.path", "is not a usable file name (NUL character or over 4096 characters)")
        if ref.id in ids:
            raise r.fail(f"{where}.id", f"duplicate dataset id {_quote(ref.id)}")
        ids.add(ref.id)
        session.datasets.append(ref)

    tfs = r.obj(d.get("transfer_functions", {}), "transfer_functions")
    for name, value in tfs.items():
        session.transfer_functions[name] = _read_transfer_function(r, value, f"transfer_functions.{name}")

    component_ids: set[str] = set()
    for i, item in enumerate(r.lst(d.get("components", []), "components")):
        where = f"components[{i}]"
        o = r.obj(item, where)
        r.known_keys(o, where, {"id", "type", "dataset", "visible", "opacity", "transfer_function", "settings"})
        comp = Component(
            id=r.string(o.get("id"), f"{where}.id"),
            type=r.string(o.get("type"), f"{where}.type", COMPONENT_TYPES),
            dataset=None if o.get("dataset") is None else r.string(o.get("dataset"), f"{where}.dataset"),
            visible=r.boolean(o.get("visible", True), f"{where}.visible"),
            opacity=r.number(o.get("opacity", 1.0), f"{where}.opacity", 0.0, 1.0),
            transfer_function=(None if o.get("transfer_function") is None
                               else r.string(o.get("transfer_function"), f"{where}.transfer_function")),
            settings=r.json_value(r.obj(o.get("settings", {}), f"{where}.settings"), f"{where}.settings"),
        )
        try:
            comp.settings = validate_settings(comp.type, comp.settings, f"{where}.settings")
        except SettingsError as exc:
            raise r.fail(*exc.problems[0]) from None
        if comp.id in component_ids:
            raise r.fail(f"{where}.id", f"duplicate component id {_quote(comp.id)}")
        component_ids.add(comp.id)
        if comp.dataset is not None and comp.dataset not in ids:
            raise r.fail(f"{where}.dataset", f"no dataset with id {_quote(comp.dataset)}")
        if comp.transfer_function is not None and comp.transfer_function not in session.transfer_functions:
            raise r.fail(f"{where}.transfer_function", f"no transfer function named {_quote(comp.transfer_function)}")
        session.components.append(comp)

    if d.get("camera") is not None:
        session.camera = r.camera(d["camera"], "camera")
    for name, keys in r.obj(d.get("camera_paths", {}), "camera_paths").items():
        path_keys = []
        last = -math.inf
        for j, key in enumerate(r.lst(keys, f"camera_paths.{name}")):
            where = f"camera_paths.{name}[{j}]"
            k = r.obj(key, where)
            r.known_keys(k, where, {"time", "camera"})
            t = r.number(k.get("time"), f"{where}.time")
            if t <= last:
                raise r.fail(f"{where}.time", "key times must increase")
            last = t
            path_keys.append(CameraKey(time=t, camera=r.camera(k.get("camera"), f"{where}.camera")))
        session.camera_paths[name] = path_keys
    for name, cam in r.obj(d.get("bookmarks", {}), "bookmarks").items():
        session.bookmarks[name] = r.camera(cam, f"bookmarks.{name}")

    rs = r.obj(d.get("render", {}), "render")
    r.known_keys(rs, "render", {"method", "size", "background", "options"})
    size = r.vector(rs.get("size", [1024, 768]), "render.size", 2)
    if any(v < 1 or v > 16384 or v != int(v) for v in size):
        raise r.fail("render.size", f"expected two whole numbers in 1..16384, got {list(size)}")
    session.render = RenderSettings(
        method=r.string(rs.get("method", "auto"), "render.method", RENDER_METHODS),
        size=(int(size[0]), int(size[1])),
        background=tuple(r.number(v, f"render.background[{i}]", 0.0, 1.0)  # type: ignore[arg-type]
                         for i, v in enumerate(r.vector(rs.get("background", [0.1, 0.1, 0.12]), "render.background"))),
        options=r.json_value(r.obj(rs.get("options", {}), "render.options"), "render.options"),
    )
    try:
        validate_render_options(session.render.options)
    except SettingsError as exc:
        raise r.fail(*exc.problems[0]) from None
    session.layout = r.json_value(r.obj(d.get("layout", {}), "layout"), "layout")
    session.clip = _read_clip(r, d.get("clip", {"planes": [], "box": None}))
    return session


def _read_options(r: _Reader, value: Any, where: str) -> dict[str, Any]:
    """Dataset options go to a reader as keyword arguments: names are identifiers and values are plain data only
    (strings, finite numbers, booleans, null, or short lists of those). Which options a reader takes is the reader
    registry's business, checked when the dataset is read."""
    options = r.obj(value, where)
    out: dict[str, Any] = {}
    for key, item in options.items():
        at = f"{where}.{key}"
        if not _OPTION_NAME.match(key):
            raise r.fail(where, "option names are identifiers (letters, digits and _, at most 64 characters)")
        if isinstance(item, list):
            if len(item) > MAX_OPTION_ITEMS:
                raise r.fail(at, f"a list of {len(item)} items; an option list holds at most {MAX_OPTION_ITEMS}")
            out[key] = [_option_scalar(r, v, f"{at}[{i}]") for i, v in enumerate(item)]
        else:
            out[key] = _option_scalar(r, item, at)
    return out


_OPTION_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}\Z")


def _option_scalar(r: _Reader, value: Any, where: str) -> Any:
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, float)):
        return r.number(value, where) if isinstance(value, float) else value
    raise r.fail(where, f"expected a string, number, boolean or null, got {_kind(value)}")


def _read_clip(r: _Reader, value: Any) -> ClipSettings:
    """Scene-wide clipping (``volviz.model.clip.ClipSettings``, libMini note Fig. 6): any number of planes
    ``{"point", "normal"}`` keeping ``(x - point)·normal >= 0`` (the normal made unit length), and an optional box
    ``{"lo", "hi"}``. Sessions written before clipping existed have no ``clip`` field and load with no clipping."""
    d = r.obj(value, "clip")
    r.known_keys(d, "clip", {"planes", "box"})
    planes: list[ClipPlane] = []
    for i, item in enumerate(r.lst(d.get("planes", []), "clip.planes")):
        where = f"clip.planes[{i}]"
        o = r.obj(item, where)
        r.known_keys(o, where, {"point", "normal"})
        normal = r.vector(o.get("normal"), f"{where}.normal")
        if math.sqrt(sum(v * v for v in normal)) < 1e-12:
            raise r.fail(f"{where}.normal", "must not be the zero vector")
        planes.append(ClipPlane(r.vector(o.get("point"), f"{where}.point"), normal))  # type: ignore[arg-type]
    box: BoxCrop | None = None
    if d.get("box") is not None:
        o = r.obj(d["box"], "clip.box")
        r.known_keys(o, "clip.box", {"lo", "hi"})
        lo, hi = r.vector(o.get("lo"), "clip.box.lo"), r.vector(o.get("hi"), "clip.box.hi")
        if any(a > b for a, b in zip(lo, hi)):
            raise r.fail("clip.box", f"needs lo <= hi on every axis, got lo={list(lo)} hi={list(hi)}")
        box = BoxCrop(lo, hi)  # type: ignore[arg-type]
    return ClipSettings(tuple(planes), box)


def _camera_dict(cam: CameraState) -> dict[str, Any]:
    return {"position": list(cam.position), "focal_point": list(cam.focal_point), "view_up": list(cam.view_up),
            "view_angle": cam.view_angle, "parallel": cam.parallel, "parallel_scale": cam.parallel_scale}


def session_to_dict(session: Session) -> dict[str, Any]:
    """The JSON document of a session (current ``VERSION``)."""
    doc: dict[str, Any] = {
        "format": FORMAT,
        "version": VERSION,
        "datasets": [{"id": d.id, "path": d.path, "options": copy.deepcopy(d.options)} for d in session.datasets],
        "transfer_functions": {name: tf.to_dict() for name, tf in session.transfer_functions.items()},
        "components": [{"id": c.id, "type": c.type, "dataset": c.dataset, "visible": c.visible, "opacity": c.opacity,
                        "transfer_function": c.transfer_function, "settings": copy.deepcopy(c.settings)}
                       for c in session.components],
        "camera": None if session.camera is None else _camera_dict(session.camera),
        "camera_paths": {name: [{"time": k.time, "camera": _camera_dict(k.camera)} for k in keys]
                         for name, keys in session.camera_paths.items()},
        "bookmarks": {name: _camera_dict(cam) for name, cam in session.bookmarks.items()},
        "render": {"method": session.render.method, "size": list(session.render.size),
                   "background": list(session.render.background), "options": copy.deepcopy(session.render.options)},
        "layout": copy.deepcopy(session.layout),
        "clip": session.clip.to_dict(),
    }
    return doc


# --------------------------------------------------------------------------------------------------------- migration
# MIGRATIONS[v] turns a version-v document into a version-(v + 1) document. Version 1 is the first format.
MIGRATIONS: dict[int, Callable[[dict[str, Any]], dict[str, Any]]] = {}


def migrate(doc: dict[str, Any], source: str | None = None) -> dict[str, Any]:
    """Check format and version; bring an older document up to ``VERSION``; refuse a newer one."""
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise SessionError(source, f"not a volviz session (expected \"format\": \"{FORMAT}\")", "format")
    version = doc.get("version")
    if isinstance(version, bool) or not isinstance(version, int) or version < 1:
        raise SessionError(source, f"expected a whole number >= 1, got {_kind(version)}", "version")
    if version > VERSION:
        raise SessionError(source, f"session version {version} is newer than this volviz supports ({VERSION}); "
                                   "please update volviz", "version")
    while version < VERSION:
        doc = MIGRATIONS[version](copy.deepcopy(doc))
        version += 1
        doc["version"] = version
    return doc


# --------------------------------------------------------------------------------------------------------- files
def resolve_path(session_file: str | os.PathLike, dataset_path: str) -> Path:
    """A dataset path as stored (relative to the session file, or absolute) made absolute."""
    p = Path(os.path.expandvars(dataset_path)).expanduser()
    return p if p.is_absolute() else (Path(session_file).resolve().parent / p).resolve()


def relative_path(session_file: str | os.PathLike, dataset_path: str | os.PathLike) -> str:
    """How a dataset path is stored: relative to the session file's folder where possible, with '/' separators."""
    target = Path(dataset_path).resolve()
    base = Path(session_file).resolve().parent
    try:
        return Path(os.path.relpath(target, base)).as_posix()
    except ValueError:  # another drive on Windows
        return target.as_posix()


def loads(text: str, source: str | os.PathLike | None = None) -> Session:
    """Parse and validate a session document held in memory (see :func:`load` for files)."""
    src = None if source is None else str(source)
    text = text.removeprefix("\ufeff")  # a UTF-8 byte-order mark decoded as text
    _check_structure(text.encode("utf-8", "surrogatepass"), src)
    try:
        doc = json.loads(text, parse_constant=lambda name: _reject_constant(name, src))
    except json.JSONDecodeError as exc:
        raise SessionError(src, f"not valid JSON: {exc.msg} at line {exc.lineno} column {exc.colno}") from None
    except (RecursionError, ValueError, MemoryError) as exc:  # bounded by _check_structure; kept as a last guard
        raise SessionError(src, f"cannot be parsed ({type(exc).__name__})") from None
    _check_sizes(doc, src)
    return session_from_dict(migrate(doc, src), src)


_NUMBER_CHARS = bytes.maketrans(b"-+0123456789.eE", b"#" * 15)


def _check_structure(data: bytes, source: str | None) -> None:
    """Bound value count, number length and nesting depth before ``json`` sees the text, with C-speed scans of the
    bytes between strings (no Python work per value): a hostile file is refused without deep recursion, slow
    big-number conversion or a huge allocation."""
    outside = outside_strings(data)
    values = outside.count(b",") + outside.count(b"[") + outside.count(b"{") + 1
    if values > MAX_VALUES:
        raise SessionError(source, f"holds about {values} values; a session holds at most {MAX_VALUES}")
    if b"#" * (MAX_NUMBER_CHARS + 1) in outside.translate(_NUMBER_CHARS, b"#"):
        raise SessionError(source, f"holds a number longer than {MAX_NUMBER_CHARS} characters")
    depth = nesting_depth(outside)
    if depth > MAX_DEPTH:
        raise SessionError(source, f"nests lists and objects {depth} deep; at most {MAX_DEPTH} are allowed")


def _check_sizes(doc: Any, source: str | None) -> None:
    """Every string, key, list and object of a parsed document within its limit; names the field that is not."""
    stack: list[tuple[Any, str]] = [(doc, "")]
    while stack:
        value, where = stack.pop()
        if isinstance(value, (dict, list)) and len(value) > MAX_ITEMS:
            raise SessionError(source, f"holds {len(value)} items; at most {MAX_ITEMS} are allowed", where or None)
        if isinstance(value, dict):
            for key, item in value.items():
                if len(key) > MAX_KEY_CHARS or not key.isprintable():
                    raise SessionError(source, f"has a key of {len(key)} characters; keys are at most "
                                               f"{MAX_KEY_CHARS} printable characters", where or None)
                if isinstance(item, (dict, list, str)):
                    stack.append((item, f"{where}.{key}" if where else key))
        elif isinstance(value, list):
            stack.extend((item, f"{where}[{i}]") for i, item in enumerate(value)
                         if isinstance(item, (dict, list, str)))
        elif isinstance(value, str) and len(value) > MAX_STRING_CHARS:
            raise SessionError(source, f"is a string of {len(value)} characters; at most {MAX_STRING_CHARS}",
                               where or None)


def _reject_constant(name: str, source: str | None) -> None:
    raise SessionError(source, f"{name} is not allowed in a session file")


def load(path: str | os.PathLike) -> Session:
    """Read and validate a session file. Raises ``SessionError`` naming the file and the offending field.

    Only a regular file is opened (a FIFO or device would block or never end); dataset paths that name a folder,
    FIFO or device are refused too (missing ones are reported when the dataset is read)."""
    p = Path(path)
    data = _read_regular(p)
    try:
        text = data.decode("utf-8-sig")  # a byte-order mark, as some Windows editors write, is dropped
    except UnicodeDecodeError:
        raise SessionError(p, "is not UTF-8 text (binary data)") from None
    session = loads(text, p)
    for i, ref in enumerate(session.datasets):
        _check_dataset_path(p, ref.path, f"datasets[{i}].path")
        _check_dataset_options(p, ref, f"datasets[{i}].options")
    return session


def _read_regular(p: Path) -> bytes:
    try:
        mode = os.stat(p).st_mode
    except FileNotFoundError:
        raise SessionError(p, "no such file") from None
    except (OSError, ValueError) as exc:
        raise SessionError(p, f"cannot be read: {getattr(exc, 'strerror', None) or exc}") from None
    if stat.S_ISDIR(mode):
        raise SessionError(p, "is a folder, not a session file")
    if not stat.S_ISREG(mode):
        raise SessionError(p, f"is {path_kind(mode)}, not a session file")
    try:  # O_NONBLOCK: should the path have become a FIFO since the stat, opening it does not wait for a writer
        fd = os.open(p, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as handle:
            st = os.fstat(handle.fileno())
            if not stat.S_ISREG(st.st_mode):
                raise SessionError(p, f"is {path_kind(st.st_mode)}, not a session file")
            if st.st_size > MAX_SESSION_BYTES:
                raise SessionError(p, f"is {st.st_size} bytes; a session file is at most {MAX_SESSION_BYTES} bytes")
            data = handle.read(MAX_SESSION_BYTES + 1)
    except OSError as exc:
        raise SessionError(p, f"cannot be read: {exc.strerror or exc}") from None
    if len(data) > MAX_SESSION_BYTES:
        raise SessionError(p, f"is over {MAX_SESSION_BYTES} bytes; a session file is at most that")
    return data


def _check_dataset_path(session_file: Path, stored: str, where: str) -> None:
    """A dataset path that exists must be a regular file or a folder that a reader opens (an OpenFOAM case ...);
    a FIFO, device or other folder is refused here, before anything tries to read it."""
    try:
        path = resolve_path(session_file, stored)
        mode = os.stat(path).st_mode
    except RuntimeError:  # Path.resolve: "Symlink loop from ..."
        raise SessionError(session_file, f"{stored} is a loop of symbolic links, not a data file", where) from None
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise SessionError(session_file, f"{stored} is a loop of symbolic links, not a data file", where) from None
        return  # missing: reported when read
    except ValueError:  # a pattern or an unresolvable name
        return
    if stat.S_ISREG(mode) or (stat.S_ISDIR(mode) and _read_as_folder(path)):
        return
    raise SessionError(session_file, f"is {path_kind(mode)}, not a data file", where)


def _check_dataset_options(session_file: Path, ref: DatasetRef, where: str) -> None:
    """The options of a dataset that exists, checked against its reader (``volviz.io.option_check``): an unknown
    option, a missing one or a value of another type is refused here, naming the field."""
    try:
        check_reader_options(resolve_path(session_file, ref.path), ref.options)
    except OptionProblem as exc:
        raise SessionError(session_file, exc.problem, f"{where}.{exc.option}" if exc.option else where) from None
    except (OSError, RuntimeError, ValueError):  # a path that cannot be resolved: reported by the path check
        return


def _read_as_folder(folder: Path) -> bool:
    return any(spec.opens_folder(folder) for spec in reader_specs())


def dumps(session: Session) -> str:
    return json.dumps(session_to_dict(session), indent=2, allow_nan=False) + "\n"


def save(session: Session, path: str | os.PathLike) -> None:
    """Validate and save atomically. Raises ``SessionError``; on failure the previous file is left intact."""
    p = Path(path)
    try:
        text = dumps(session)
    except (TypeError, ValueError) as exc:
        raise SessionError(p, f"cannot be saved: {exc}") from None
    session_from_dict(json.loads(text), p)  # never write what could not be read back
    try:
        atomic_write_bytes(p, text.encode("utf-8"))
    except OutputPathError as exc:
        raise SessionError(p, f"cannot be written: {exc.problem}") from None
    except OSError as exc:
        raise SessionError(p, f"cannot be written: {exc.strerror or exc}") from None


# ------------------------------------------------------------------------------------------------- missing data
@dataclass(frozen=True)
class MissingFile:
    """A dataset of a session whose file is not where the session says: its ``dataset`` id, the path as ``stored``
    and the ``expected`` absolute path it was looked for at."""

    dataset: str
    stored: str
    expected: Path


_UNSET_VARIABLE = re.compile(r"\$(\w+)|\$\{(\w+)\}")
LOCATE_ENTRIES = 50_000  # folder entries a search for missing files looks at, at most (a home folder is not walked)


def missing_files(session: Session, session_file: str | os.PathLike | None,
                  ids: set[str] | None = None) -> list[MissingFile]:
    """The datasets (those in ``ids``, else all) whose files do not exist, in the session's order."""
    missing = []
    for ref in session.datasets:
        if ids is not None and ref.id not in ids:
            continue
        expected = resolve_path(session_file, ref.path) if session_file else Path(os.path.expandvars(ref.path))
        if not _present(expected):
            missing.append(MissingFile(ref.id, ref.path, expected))
    return missing


def _present(path: Path) -> bool:
    """Whether a dataset path names something there: a file or folder, or a numbered series' pattern
    (``quarter.%d``, ``Storm.pvm-t*``) that some file matches."""
    if path.exists():
        return True
    if not re.search(r"%0?\d*d|[*?\[]", path.name):
        return False
    try:
        return any(p.exists() for _, p in expand_pattern(str(path)))
    except (ReadError, OSError):
        return False


def unset_variables(missing: list[MissingFile]) -> list[str]:
    """The environment variables the missing files' stored paths use that are not set (``$VOLVIZ_DATA``)."""
    names = {a or b for f in missing for a, b in _UNSET_VARIABLE.findall(f.stored)}
    return sorted(n for n in names if not os.environ.get(n))


def missing_message(missing: list[MissingFile]) -> str:
    """One line naming each missing file and what to do."""
    unset = unset_variables(missing)
    files = "; ".join(f"{f.dataset}: {f.stored}" + ("" if str(f.expected) == f.stored or unset_variables([f])
                                                     else f" (looked for {f.expected})") for f in missing)
    hint = (f"set {', '.join(unset)} to the folder that holds them" if unset
            else "put the files back, or open the session in volviz-app and locate the folder that holds them")
    return f"{len(missing)} data file{'s' if len(missing) > 1 else ''} not found: {files}; {hint}"


def _tails(stored: str) -> list[Path]:
    """The stored path's endings, longest first, after any environment variable or absolute prefix:
    ``$VOLVIZ_DATA/yukon/Yukon.map.pgm`` -> ``yukon/Yukon.map.pgm``, ``Yukon.map.pgm``."""
    text = _UNSET_VARIABLE.sub("", stored).replace("\\", "/")
    parts = [p for p in text.split("/") if p not in ("", ".", "..", "~")]
    return [Path(*parts[i:]) for i in range(len(parts))]


def locate_missing(missing: list[MissingFile], folders: list[Path],
                   max_entries: int = LOCATE_ENTRIES) -> dict[str, Path]:
    """Where the ``missing`` files are under ``folders``: first the stored path's endings directly under each folder
    (``yukon/Yukon.map.pgm``), then the file's name anywhere below it (at most ``max_entries`` entries looked at
    in all). Returns dataset id -> the file found."""
    found: dict[str, Path] = {}
    for f in missing:
        for folder in folders:
            hit = next((folder / t for t in _tails(f.stored) if (folder / t).is_file()), None)
            if hit is not None:
                found[f.dataset] = hit.resolve()
                break
    wanted = {Path(f.stored).name: f.dataset for f in missing if f.dataset not in found}
    seen = 0
    for folder in folders:
        if not wanted:
            break
        for root, dirs, files in os.walk(folder):
            dirs.sort()
            seen += len(dirs) + len(files)
            for name in sorted(set(files) & set(wanted)):
                found[wanted.pop(name)] = (Path(root) / name).resolve()
            if seen > max_entries or not wanted:
                break
    return found
