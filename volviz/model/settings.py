"""Typed, validated settings of every component kind and the render options of a session (pydantic v2 models).

Each component type of a session (``volviz.session.COMPONENT_TYPES``) has one settings model here; the session
loader validates a component's ``settings`` object against it (``validate_settings``), so an unknown key, a wrong
type or a value out of range is refused with the field's path, and the defaults live in one place (the model)
instead of in the ``.get(key, default)`` calls of the code that uses them. ``RenderOptions`` does the same for
``render.options``. Every option with a fixed set of values is a ``Literal`` defined once below; the app builds its
settings forms from these models (field titles, descriptions, bounds, units in ``json_schema_extra``; a field that
applies only to some datasets is marked ``APPLIES_TO``, ``volviz.model.applicability``), and ``volviz schema``
exports them as part of the session's JSON schema (``volviz.model.session_schema``).
"""
from __future__ import annotations

from typing import Any, Literal, Optional, TypeVar, Union

from pydantic import AliasChoices, BaseModel, ConfigDict, Field, ValidationError, field_validator

__all__ = ["Settings", "TerrainSettings", "FogSettings", "CloudSettings", "SkySettings", "VolumeSettings",
           "MeshSettings", "IsoStyleSettings", "IsosurfaceSettings", "DemoSettings", "RenderOptions",
           "SETTINGS_MODELS", "FogMode", "CloudShadingName", "IsoMode", "IsoShading", "IsoOverlayMode", "Backend",
           "GpuThread", "SortName", "APPLIES_TO", "array_key", "settings_model", "former_names", "validate_settings",
           "validate_render_options", "typed_settings", "validated", "SettingsError",
           "ScalarBarStyle", "SlicesSettings"]

FogMode = Literal["emissive", "attenuated", "mip"]
CloudShadingName = Literal["npr", "physical"]
IsoMode = Literal["2pass", "3pass", "4pass", "exact"]
IsoOverlayMode = Literal["vtk", "2pass", "3pass", "4pass", "exact"]
IsoShading = Literal["spectrum", "flat"]
Backend = Literal["auto", "gpu", "cpu"]
GpuThread = Literal["auto", "on", "off"]
SortName = Literal["mpvo", "centroid", "power"]
TableName = Literal["auto", "3d", "separable-1", "separable-2", "separable-4"]

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]
Color = tuple[float, float, float]


#: the ``json_schema_extra`` key of a field that applies only to some datasets: the dataset trait (or list of traits)
#: it needs (``volviz.model.applicability``)
APPLIES_TO = "applies_to"


def _unit(unit: str) -> dict[str, Any]:
    return {"unit": unit}


def _applies_to(trait: str) -> dict[str, Any]:
    return {APPLIES_TO: trait}


class SettingsError(ValueError):
    """Settings that do not fit their model: ``problems`` are ``(field path, message)`` pairs."""

    def __init__(self, problems: list[tuple[str, str]]) -> None:
        self.problems = problems
        super().__init__("; ".join(f"{path}: {message}" if path else message for path, message in problems))


class Settings(BaseModel):
    """Base of every settings model: unknown keys are refused, values are checked on assignment too."""

    model_config = ConfigDict(extra="forbid", validate_assignment=True, populate_by_name=True)


class TerrainSettings(Settings):
    """Terrain C-LOD (Roettger Ch. 9): a height map dataset, or a procedural fractal terrain without one."""

    size: Optional[int] = Field(None, ge=3, le=8193, title="Grid size",
                                description="points per side: of the procedural terrain (default 257), or the height "
                                            "map resampled to it")
    seed: int = Field(1, ge=0, title="Seed", description="random seed of the procedural terrain")
    relief: float = Field(160.0, gt=0, le=1e6, title="Relief", description="height range of the procedural terrain",
                          json_schema_extra=_unit("m"))
    extent: Optional[Vec2] = Field(None, title="Extent", description="world size (x, y); default: the height map's "
                                   "spacing, or 1000 x 1000 for the procedural terrain", json_schema_extra=_unit("m"))
    height_scale: float = Field(1.0, gt=0, le=1e6, title="Height scale", description="heights multiplied by this")
    origin: Optional[Vec2] = Field(None, title="Origin", description="the terrain's corner (x, y; e.g. UTM "
                                   "coordinates moved to the origin)", json_schema_extra=_unit("m"))
    C: float = Field(12.0, gt=0, le=1e4, title="Global resolution C", description="C-LOD: the larger, the finer "
                     "(Roettger §9.2, d/l < C)")
    c: float = Field(60.0, gt=0, le=1e5, title="Local resolution c", description="C-LOD: the larger, the more "
                     "roughness is refined (§9.2, d/(l·d2) < c)")
    texture_dataset: Optional[str] = Field(None, title="Texture", description="id of an RGB image dataset draped "
                                           "over the terrain", json_schema_extra={"dataset": True})


class FogSettings(Settings):
    """Ground fog / cloud layer: PCP prisms on the terrain (Roettger §10.3)."""

    level: float = Field(50.0, title="Level", description="height of the procedural fog's surface",
                         json_schema_extra=_unit("m"))
    thickness: float = Field(25.0, ge=0, title="Thickness", description="thickness of the procedural fog",
                             json_schema_extra=_unit("m"))
    seed: int = Field(2, ge=0, title="Seed", description="random seed of the procedural fog map")
    thickness_scale: float = Field(1.0, ge=0, title="Thickness scale", description="fog-map values (the "
                                   "component's dataset) times this give the thickness")
    base_dataset: Optional[str] = Field(None, title="Base", description="id of an image dataset giving the layer's "
                                        "bottom height (a cloud layer); default: the terrain",
                                        json_schema_extra={"dataset": True})
    base_scale: float = Field(1.0, title="Base scale", description="base-map values times this")
    base_offset: float = Field(0.0, title="Base offset", description="added to the base height",
                               json_schema_extra=_unit("m"))
    # "colour": the name sessions were saved with before the public API spelt it "color" (read, saved as "color")
    color: Color = Field((0.75, 0.75, 1.0), title="Color", json_schema_extra={"color": True},
                         validation_alias=AliasChoices("color", "colour"))
    density: float = Field(0.05, ge=0, le=1e3, title="Density", description="emission / optical density per unit "
                           "length at emission 1", json_schema_extra=_unit("1/m"))
    mode: FogMode = Field("attenuated", title="Mode", description="emissive (additive), attenuated (the integral as "
                          "optical depth) or mip (§10.4)")
    mip_gain: float = Field(0.05, ge=0, title="MIP gain", description="intensity per unit of layer thickness")
    weight: float = Field(4.0, ge=0, le=1e3, title="LOD weight", description="how much the layer refines the "
                          "terrain mesh under it")

    @field_validator("color")
    @classmethod
    def _color_in_range(cls, value: Color) -> Color:
        if any(not 0.0 <= v <= 1.0 for v in value):
            raise ValueError("color components must be in 0..1")
        return value


class CloudSettings(Settings):
    """Volumetric C-LOD clouds (Roettger Ch. 11): a density dataset, or procedural Perlin clouds without one."""

    shape: tuple[int, int, int] = Field((129, 129, 17), title="Grid shape", description="samples of the procedural "
                                        "cloud volume (x, y, z); each 3..1025")
    seed: int = Field(3, ge=0, title="Seed")
    coverage: float = Field(0.25, ge=0, le=1, title="Coverage", description="share of the sky the procedural clouds "
                            "cover")
    extent: Optional[Vec2] = Field(None, title="Extent", description="world size (x, y); default: the terrain's",
                                   json_schema_extra=_unit("m"))
    thickness: Optional[float] = Field(None, gt=0, title="Thickness", description="vertical size; default: the "
                                       "grid's aspect", json_schema_extra=_unit("m"))
    base_height: float = Field(190.0, title="Base height", json_schema_extra=_unit("m"))
    shading: CloudShadingName = Field("npr", title="Shading", description="npr (non-photorealistic, §11.6) or physical")
    rho_max: float = Field(0.06, gt=0, le=10, title="Maximum density", description="optical density of the densest "
                           "cloud", json_schema_extra=_unit("1/m"))
    C: float = Field(2.0, gt=0, le=1e4, title="Global resolution C", description="cloud C-LOD (§11.3)")
    c: float = Field(8.0, gt=0, le=1e5, title="Local resolution c")

    @field_validator("shape")
    @classmethod
    def _shape_in_range(cls, value: tuple[int, int, int]) -> tuple[int, int, int]:
        if any(not 3 <= v <= 1025 for v in value):
            raise ValueError("each size must be in 3..1025")
        return value


class SkySettings(Settings):
    """The sky dome (no settings)."""


class VolumeSettings(Settings):
    """A volume: regular (ray cast, LOD from .vvz) or unstructured (projected tetrahedra)."""

    array: Optional[str] = Field(None, title="Array", description="the shown array (NAME, NAME:component, "
                                 "NAME:magnitude); default: the dataset's first", json_schema_extra={"array": True})
    budget: int = Field(256, ge=1, le=1 << 20, title="Block budget", description="compressed .vvz volumes drawn at "
                        "a level of detail: blocks decoded per view", json_schema_extra=_applies_to("lod_volume"))
    interpolate: bool = Field(True, title="Interpolate in time", description="time series: blend the two nearest "
                              "steps", json_schema_extra=_applies_to("time_series"))
    log_scale: bool = Field(False, title="Log color scale", description="color and opacity of log10 of the value "
                            "(values <= 0 take the color of the smallest positive value)")
    shade: bool = Field(False, title="Shading", description="lighting of regular (uncompressed) volumes from the "
                        "scalar's gradient: ambient, diffuse and specular; other volumes are drawn unlit")


class MeshSettings(VolumeSettings):
    """A surface mesh or a mesh shown as a volume."""


class IsoStyleSettings(Settings):
    """One isosurface: its value, color and opacity."""

    value: float = Field(title="Iso-value")
    color: Color = Field((1.0, 1.0, 1.0), title="Color", json_schema_extra={"color": True})
    opacity: float = Field(0.5, ge=0, le=1, title="Opacity")


class IsosurfaceSettings(Settings):
    """Several semi-transparent isosurfaces of one volume (libMini note §4)."""

    styles: list[IsoStyleSettings] = Field(default_factory=list, max_length=64, title="Surfaces")
    mode: IsoMode = Field("4pass", title="Transparency mode")
    shading: IsoShading = Field("spectrum", title="Shading")
    clip: dict[str, Any] = Field(default_factory=lambda: {"planes": [], "box": None}, title="Clipping",
                                 description="planes and box of this component (volviz.iso.clip)")
    lod: bool = Field(False, title="Level of detail")
    triangles_per_pixel2: float = Field(0.25, gt=0, le=100, title="Triangles per pixel²", description="LOD target")
    interpolate: bool = Field(True, title="Interpolate in time", description="time series: blend the two nearest "
                              "steps", json_schema_extra=_applies_to("time_series"))
    scalars: Optional[str] = Field(None, title="Array", json_schema_extra={"array": True})


class SlicesSettings(Settings):
    """Axis-aligned planes through a regular volume, coloured by the component's transfer function
    (``volviz.render.slices``); an index of null: that plane is off."""

    x: Optional[int] = Field(None, ge=0, title="X slice", description="grid index of the plane x = const")
    y: Optional[int] = Field(None, ge=0, title="Y slice", description="grid index of the plane y = const")
    z: Optional[int] = Field(None, ge=0, title="Z slice", description="grid index of the plane z = const")
    array: Optional[str] = Field(None, title="Array", json_schema_extra={"array": True})


class DemoSettings(Settings):
    """The built-in demo volume (a tetrahedralised analytic field)."""

    cells_per_edge: int = Field(20, ge=2, le=200, title="Cells per edge")
    array: Optional[str] = Field(None, title="Array", json_schema_extra={"array": True})


#: the settings model of each component type
SETTINGS_MODELS: dict[str, type[Settings]] = {
    "terrain": TerrainSettings, "fog": FogSettings, "clouds": CloudSettings, "sky": SkySettings,
    "volume": VolumeSettings, "mesh": MeshSettings, "isosurface": IsosurfaceSettings, "demo": DemoSettings,
    "slices": SlicesSettings,
}


#: a printf format of one number: flags, width, precision, one of f e g (and capitals); text around it, no other %
LABEL_FORMAT = r"^[^%]{0,16}%[-+ #0]{0,4}[0-9]{0,2}(\.[0-9]{1,2})?[feEgG][^%]{0,16}$"


class ScalarBarStyle(Settings):
    """What the scalar bar shows when it is edited (View > Edit Scalar Bar): each unset field follows the data."""

    title: Optional[str] = Field(None, max_length=200, title="Title", description="default: the shown array's name")
    range: Optional[Vec2] = Field(None, title="Range", description="a fixed range of the bar; default: the transfer "
                                  "function's")
    format: Optional[str] = Field(None, pattern=LABEL_FORMAT, title="Number format", description="printf format of "
                                  "the labels, e.g. %.3g; default: chosen from the range")

    @field_validator("range")
    @classmethod
    def _increasing(cls, value: Optional[Vec2]) -> Optional[Vec2]:
        if value is not None and not value[0] < value[1]:
            raise ValueError("the range's low end must be below its high end")
        return value


class RenderOptions(Settings):
    """``render.options`` of a session: how every view is drawn."""

    backend: Backend = Field("auto", title="Backend", description="gpu (VTK's OpenGL with volviz's shaders), cpu "
                             "(volviz's own renderers), or auto (the GPU on a hardware driver; on a software "
                             "rasteriser the one measured faster)")
    gpu_thread: GpuThread = Field("auto", title="GPU volumes in a thread", description="the app draws GPU PT volumes "
                                  "in a window of a thread of their own, shown over the scene as an image: on, off "
                                  "(in the scene's window), or auto (on a software rasteriser, whose raster is CPU "
                                  "work that would hold the window)")
    sort: SortName = Field("mpvo", title="Cell sort", description="PT visibility order: mpvo (exact for convex "
                           "meshes, with Guthe's boundary relations otherwise), centroid or power")
    table: TableName = Field("auto", title="Pre-integration table", description="auto (by optical depth), 3d, or "
                             "separable with a color polynomial of degree 1, 2 or 4 (Roettger §9.1)")
    table_resolution: int = Field(128, ge=16, le=1024, title="Table resolution")
    iso_mode: IsoOverlayMode = Field("vtk", title="Isosurface mode", description="vtk (VTK's own blending) or a "
                                     "transparency mode of the libMini note")
    error_budget: Optional[float] = Field(None, gt=0, le=255, title="Error budget", description="largest RMSE (8-bit "
                                          "units) a faster, approximate setting may cost while the camera moves")
    time: Optional[float] = Field(None, title="Time", description="the display time of time series")
    fly_clearance: float = Field(0.01, ge=0, le=0.5, title="Fly clearance", description="fly mode keeps this share "
                                 "of the scene's size from opaque geometry")
    scalar_bar: bool = Field(True, title="Scalar bar")
    scalar_bar_style: ScalarBarStyle = Field(default_factory=ScalarBarStyle, title="Scalar bar style")
    axes: bool = Field(True, title="Axes")
    outline: bool = Field(True, title="Outline box")


def array_key(component_type: str) -> str:
    """The settings key naming the array a component shows: ``scalars`` for isosurfaces, ``array`` otherwise."""
    return "scalars" if component_type == "isosurface" else "array"


def settings_model(component_type: str) -> type[Settings]:
    """The settings model of a component type (KeyError for an unknown type)."""
    return SETTINGS_MODELS[component_type]


def _kind(value: Any) -> str:
    """What a JSON value is, in words (as the session loader says it)."""
    for types, word in ((bool, "true or false"), ((int, float), "a number"), (str, "a string"), (list, "a list"),
                        (dict, "an object"), (type(None), "null")):
        if isinstance(value, types):
            return word
    return type(value).__name__


_EXPECTED = {"string_type": "a string", "bool_type": "true or false", "bool_parsing": "true or false",
             "int_type": "a whole number", "int_parsing": "a whole number", "int_from_float": "a whole number",
             "float_type": "a number", "float_parsing": "a number", "finite_number": "a finite number",
             "tuple_type": "a list", "list_type": "a list", "dict_type": "an object", "model_type": "an object"}


def _message(err: Any) -> str:
    """A pydantic error in the words of the session loader: choices listed, the kind of a wrong value named."""
    kind, value = err["type"], err.get("input")
    if kind == "extra_forbidden":
        return "unknown setting"
    if kind == "literal_error":  # every Literal here is of strings
        if not isinstance(value, str):
            return f"expected a string, got {_kind(value)}"
        choices = [c.strip().strip("'") for c in err["ctx"]["expected"].replace(" or ", ", ").split(",")]
        return f"expected one of {', '.join(choices)}, got {value!r}"
    if kind in _EXPECTED:
        return f"expected {_EXPECTED[kind]}, got {_kind(value)}"
    return str(err["msg"])


def _problems(exc: ValidationError, where: str) -> list[tuple[str, str]]:
    out = []
    for err in exc.errors():
        loc = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in err["loc"])
        out.append((f"{where}{loc}", _message(err)))
    return out


M = TypeVar("M", bound=Settings)


def validated(model: type[M], settings: dict[str, object], where: str = "settings") -> M:
    """``settings`` as an instance of ``model`` (SettingsError naming the field path of each problem)."""
    try:
        return model.model_validate(settings)
    except ValidationError as exc:
        raise SettingsError(_problems(exc, where)) from None


def typed_settings(component_type: str, settings: dict[str, object], where: str = "settings") -> Settings:
    """The model instance of a component's settings (``validated`` by ``SETTINGS_MODELS[component_type]``); a caller
    that knows the type asks ``validated(FogSettings, ...)`` for the typed model."""
    return validated(settings_model(component_type), settings, where)


def former_names(component_type: str) -> dict[str, str]:
    """The keys older sessions wrote for a component type's fields that have since been renamed, each with the
    field's name now (the other choices of a field's ``validation_alias``): ``{"colour": "color"}`` for fog."""
    former = {}
    for name, info in settings_model(component_type).model_fields.items():
        if isinstance(info.validation_alias, AliasChoices):
            former.update({key: name for key in info.validation_alias.choices if isinstance(key, str) and key != name})
    return former


def validate_settings(component_type: str, settings: dict[str, object], where: str = "settings") -> dict[str, object]:
    """``settings`` checked against its model; returned with only the keys set, as sessions store them, a key
    written under a field's former name (``former_names``) under its name now, so that a session saves it so."""
    typed_settings(component_type, settings, where)
    former = former_names(component_type)
    return {former.get(key, key): value for key, value in settings.items()}


def validate_render_options(options: dict[str, object], where: str = "render.options") -> RenderOptions:
    """``render.options`` as a ``RenderOptions`` (SettingsError naming the field path of each problem)."""
    try:
        return RenderOptions.model_validate(options)
    except ValidationError as exc:
        raise SettingsError(_problems(exc, where)) from None


AnySettings = Union[tuple(SETTINGS_MODELS.values())]  # type: ignore[valid-type]
