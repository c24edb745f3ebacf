"""The JSON schema of a session file (``volviz schema``), built from the typed settings models.

``SessionDocument`` describes the document ``volviz.session.save`` writes: its datasets, its components (one model
per component type, told apart by ``type``, each with the settings model of ``volviz.model.settings``), transfer
functions, cameras, render settings with ``RenderOptions``, layout and clipping. The session loader
(``volviz.session.load``) checks sizes, nesting, paths and references first and validates every component's
settings and the render options against the same models, so the schema and the loader agree on every field.
"""
from __future__ import annotations

import json
from typing import TYPE_CHECKING, Annotated, Any, Literal, Optional, Union

from pydantic import BaseModel, ConfigDict, Field, create_model

from volviz.model.settings import SETTINGS_MODELS, RenderOptions, Vec3

SCHEMA_ID = "https://volviz.org/schema/session-1.json"


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class DatasetDoc(_Strict):
    id: str = Field(min_length=1)
    path: str = Field(min_length=1, max_length=4096, description="relative to the session file, or absolute")
    options: dict[str, Union[str, float, bool, None, list[Union[str, float, bool, None]]]] = Field(
        default_factory=dict, description="keyword options of the dataset's reader")


class _ComponentDoc(_Strict):
    id: str = Field(min_length=1)
    dataset: Optional[str] = None
    visible: bool = True
    opacity: float = Field(1.0, ge=0, le=1)
    transfer_function: Optional[str] = None


def _component_doc(kind: str, settings: type[BaseModel]) -> type[_ComponentDoc]:
    """The document model of a component of type ``kind``: the common fields and its settings model."""
    return create_model(f"{kind.capitalize()}Component", __base__=_ComponentDoc,
                        type=(Literal[kind], ...),  # type: ignore[arg-type]  # a Literal made at run time
                        settings=(settings, Field(default_factory=settings)))


if TYPE_CHECKING:  # a union of models made at run time: to mypy, their common base
    ComponentDoc = _ComponentDoc
else:
    ComponentDoc = Annotated[Union[tuple(_component_doc(k, m) for k, m in SETTINGS_MODELS.items())],
                             Field(discriminator="type")]


class CameraDoc(_Strict):
    position: Vec3 = (1.0, 1.0, 1.0)
    focal_point: Vec3 = (0.0, 0.0, 0.0)
    view_up: Vec3 = (0.0, 0.0, 1.0)
    view_angle: float = Field(30.0, gt=0, lt=180, description="full vertical angle", json_schema_extra={"unit": "°"})
    parallel: bool = False
    parallel_scale: float = Field(1.0, gt=0)


class CameraKeyDoc(_Strict):
    time: float
    camera: CameraDoc


class RenderDoc(_Strict):
    method: Literal["auto", "pt", "reference", "vtk"] = "auto"
    size: tuple[int, int] = (1024, 768)
    background: tuple[float, float, float] = (0.1, 0.1, 0.12)
    options: RenderOptions = Field(default_factory=RenderOptions)


class TransferFunctionDoc(_Strict):
    """A piecewise-linear transfer function (``volviz.optics.TransferFunction.to_dict``, Roettger §7.1): at each
    control point a chromaticity κ (RGB) and an extinction ρ per unit length, linear between them."""

    format: Literal["volviz-transfer-function"] = "volviz-transfer-function"
    version: Literal[1] = 1
    name: str = ""
    scalars: list[float] = Field(min_length=2, description="control-point scalars, strictly increasing")
    colors: list[tuple[float, float, float]] = Field(min_length=2, description="κ >= 0 at each control point")
    extinction: list[float] = Field(min_length=2, description="ρ >= 0 at each control point, per unit length")


class ClipPlaneDoc(_Strict):
    point: Vec3
    normal: Vec3


class ClipBoxDoc(_Strict):
    lo: Vec3
    hi: Vec3


class ClipDoc(_Strict):
    planes: list[ClipPlaneDoc] = Field(default_factory=list)
    box: Optional[ClipBoxDoc] = None


class SessionDocument(_Strict):
    """A volviz session file."""

    format: Literal["volviz-session"] = "volviz-session"
    version: Literal[1] = 1
    datasets: list[DatasetDoc] = Field(default_factory=list)
    components: list[ComponentDoc] = Field(default_factory=list)
    transfer_functions: dict[str, TransferFunctionDoc] = Field(default_factory=dict,
                                                               description="named transfer functions")
    camera: Optional[CameraDoc] = None
    camera_paths: dict[str, list[CameraKeyDoc]] = Field(default_factory=dict)
    bookmarks: dict[str, CameraDoc] = Field(default_factory=dict)
    render: RenderDoc = Field(default_factory=RenderDoc)
    layout: dict[str, Any] = Field(default_factory=dict)
    clip: ClipDoc = Field(default_factory=ClipDoc)


def session_schema() -> dict[str, object]:
    """The JSON schema (draft 2020-12) of a session file."""
    schema = SessionDocument.model_json_schema()
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", "$id": SCHEMA_ID, **schema}


def session_schema_text() -> str:
    """``session_schema`` as the text ``volviz schema`` prints (and ``docs/session.schema.json`` holds)."""
    return json.dumps(session_schema(), indent=1, ensure_ascii=False) + "\n"
