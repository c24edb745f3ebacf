"""Natural scenes: terrain + ground fog / cloud layers + volumetric clouds + sky, on the CPU.

``NatureScene`` holds the pieces (terrain C-LOD with its morphed layers, PCP prism layers, cloud C-LOD, sky) and
renders a frame on the CPU (``render``): the terrain z-buffer and color (``raster``), the sky behind it, and the
volumes as one premultiplied RGBA overlay clipped at the terrain depth. Volumes are composited as layers, farthest
(from the eye's height) first — exact for layers that do not interleave along a ray (each prism layer is itself order
independent, see ``fog``; the clouds are sorted by the octree).

A scene is shown in a plotter by ``volviz.render.nature_view.NatureView`` (CPU backend) or
``volviz.render.gl_nature.GLNatureView`` (GPU backend); this package builds no VTK actors.

Session components (``scene_from_components``): "terrain", "fog" (ground fog or, with ``base_dataset``, a cloud
layer between two height fields), "clouds" (generated Perlin clouds or a volume dataset), "sky".
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from volviz.model.camera import Camera
from volviz.model.settings import CloudSettings, FogSettings, TerrainSettings, validated
from volviz.nature.clouds import CloudLOD, CloudShading, CloudVolume, build_cloud_table, render_cloud_image
from volviz.nature.fog import FogLayer, render_layer
from volviz.nature.heightfield import HeightField, grid_from_image, resample_bilinear
from volviz.nature.raster import bake_color_map, mip_pyramid, render_sky, render_terrain
from volviz.nature.terrain import TerrainLOD, TerrainMesh, frustum_planes


def over(front: np.ndarray, back: np.ndarray) -> np.ndarray:
    """Premultiplied "over": front + (1 − α_front) back."""
    return front + (1.0 - front[..., 3:4]) * back


@dataclass
class NatureFrame:
    """One CPU frame: final RGB (H, W, 3), the volume overlay (premultiplied RGBA), terrain depth and statistics."""

    rgb: np.ndarray
    overlay: np.ndarray
    depth: np.ndarray
    stats: dict[str, float] = field(default_factory=dict)
    mesh: TerrainMesh | None = None


@dataclass
class _Fog:
    name: str
    layer: FogLayer
    bottom: str
    top: str
    mid_height: float


class NatureScene:
    """Terrain, prism layers, clouds and sky; call ``finalize()`` after adding layers (or let ``render`` do it)."""

    def __init__(self, terrain: HeightField | None = None, texture: np.ndarray | None = None,
                 sky: np.ndarray | None = None, big_c: float = 12.0, small_c: float = 60.0,
                 light: Sequence[float] = (0.4, 0.3, 0.85)) -> None:
        self.terrain = terrain
        self.texture = texture
        self.sky = sky
        self.big_c = float(big_c)
        self.small_c = float(small_c)
        self.light = tuple(float(v) for v in light)
        self._layers: dict[str, np.ndarray] = {}
        self._curvature: list[tuple[np.ndarray, float]] = []
        self.fogs: list[_Fog] = []
        self.cloud_lod: CloudLOD | None = None
        self.cloud_shading: CloudShading | None = None
        self.cloud_table: Any = None
        self.lod: TerrainLOD | None = None
        self.color_map: np.ndarray | None = None
        self._pyramid: Any = None
        self._texture_image: np.ndarray | None = None

    # ----------------------------------------------------------------------------------------------- building
    def _grid(self, values: np.ndarray) -> np.ndarray:
        if self.terrain is None:
            raise ValueError("prism layers need a terrain")
        return resample_bilinear(np.asarray(values, dtype=np.float64), (self.terrain.size, self.terrain.size))

    def add_fog(self, name: str, thickness: np.ndarray, layer: FogLayer | None = None, base: np.ndarray | None = None,
                weight: float = 4.0) -> None:
        """A prism layer: ``thickness`` (x-major grid, any size, world units) above ``base`` (absolute heights; None:
        the terrain, i.e. ground fog). ``weight`` scales the thickness map's d2 in the C-LOD criterion (§10.4)."""
        if name in self._layers or f"{name}_base" in self._layers:
            raise ValueError(f"duplicate layer name {name!r}")
        thick = np.maximum(self._grid(thickness), 0.0)
        assert self.terrain is not None
        if base is None:
            bottom_name, bottom = "terrain", self.terrain.heights
        else:
            bottom_name, bottom = f"{name}_base", self._grid(base)
            self._layers[bottom_name] = bottom
        self._layers[name] = bottom + thick
        if weight > 0:
            self._curvature.append((thick, float(weight)))
        present = thick > 0
        mid = float(np.mean((bottom + 0.5 * thick)[present])) if present.any() else float(np.mean(bottom))
        self.fogs.append(_Fog(name, layer or FogLayer(), bottom_name, name, mid))
        self.lod = None

    def add_clouds(self, volume: CloudVolume, shading: CloudShading | None = None, big_c: float = 2.0,
                   small_c: float = 8.0, table_size: tuple[int, int] = (64, 128), optical: bool = True) -> None:
        """Volumetric clouds (Ch. 11) with their C-LOD and pre-integration table. ``optical``: the LOD's Δ is the
        optical-depth error Δ ρ_max s of a node (``CloudLOD(extinction=...)``), not the bare field deviation."""
        self.cloud_shading = shading or CloudShading.npr()
        ext = self.cloud_shading.tf.max_extinction if optical else 0.0
        self.cloud_lod = CloudLOD(volume, big_c=big_c, small_c=small_c, cutoff=self.cloud_shading.cutoff,
                                  extinction=ext)
        l_max = volume.root * float(np.linalg.norm(volume.spacing))
        self.cloud_table = build_cloud_table(self.cloud_shading, l_max, n_s=table_size[0], n_l=table_size[1])

    def finalize(self) -> None:
        if self.terrain is not None and self.lod is None:
            self.lod = TerrainLOD(self.terrain, layers=self._layers, curvature=self._curvature, big_c=self.big_c,
                                  small_c=self.small_c)
            if self.color_map is None:
                self.color_map = bake_color_map(self.terrain.normals(), self.texture, self.light)
                self._pyramid = mip_pyramid(self.color_map)
        if self.color_map is not None and self._texture_image is None:
            self._texture_image = _texture_bytes(self.color_map)

    def texture_image(self) -> np.ndarray | None:
        """The baked color map as the 8-bit RGB image of the terrain's texture (rows from the top, x across; None
        without a terrain), made by ``finalize``: on the worker that prepares the scene, not by the view that the
        GUI thread makes (issue #28: no event-loop stall over 100 ms)."""
        self.finalize()
        return self._texture_image

    # ----------------------------------------------------------------------------------------------- rendering
    def terrain_mesh(self, camera: Any, size: tuple[int, int], full: bool = False,
                     emit_threads: Callable[[], int] | None = None, detail: float = 1.0) -> TerrainMesh | None:
        """The terrain's C-LOD mesh for ``camera`` in a window of ``size`` (``full``: every triangle), culled to the
        view frustum with a margin; ``emit_threads`` and ``detail`` (< 1: coarser) as ``TerrainLOD.update``'s."""
        self.finalize()
        if self.lod is None:
            return None
        if full:
            return self.lod.full_mesh()
        return self.lod.update(camera.position, frustum_planes(camera, size, margin=0.05), emit_threads, detail)

    def volume_order(self, eye: Sequence[float]) -> list[tuple[str, Any]]:
        """The volume layers in compositing order for an eye position: ("fog", _Fog) per prism layer and
        ("clouds", None), farthest (by |eye height - the layer's mid height|) first; both backends composite them so
        (exact for layers that do not interleave along a ray)."""
        eye_z = float(eye[2])
        items: list[tuple[float, str, Any]] = [(abs(eye_z - fog.mid_height), "fog", fog) for fog in self.fogs]
        if self.cloud_lod is not None:
            b = self.cloud_lod.volume.bounds()
            items.append((abs(eye_z - 0.5 * (b[4] + b[5])), "clouds", None))
        items.sort(key=lambda it: -it[0])  # farthest layer first
        return [(kind, fog) for _, kind, fog in items]

    def render_volumes(self, camera: Any, size: tuple[int, int], mesh: TerrainMesh | None, depth: np.ndarray,
                       full: bool = False, stats: dict[str, float] | None = None) -> np.ndarray:
        """The premultiplied RGBA overlay of every prism layer and the clouds, clipped at ``depth``."""
        w, h = size
        stats = {} if stats is None else stats
        overlay = np.zeros((h, w, 4))
        stats.setdefault("fog_prisms", 0.0)
        stats.setdefault("fog_s", 0.0)
        for kind, fog in self.volume_order(camera.position):
            t0 = time.perf_counter()
            if kind == "fog" and mesh is not None:
                bottom = mesh.points[:, 2] if fog.bottom == "terrain" else mesh.layers[fog.bottom]
                rgba, drawn = render_layer(mesh.points, bottom, mesh.layers[fog.top], mesh.triangles, fog.layer, camera,
                                           size, depth)
                stats["fog_prisms"] += drawn
                stats["fog_s"] += time.perf_counter() - t0
            else:
                assert self.cloud_lod is not None and self.cloud_shading is not None    # add_clouds sets both
                frame = self.cloud_lod.update(camera, size, full=full)
                rgba = render_cloud_image(frame, self.cloud_shading, self.cloud_table, camera, size, depth)
                stats["cloud_tets"] = float(frame.n_tets)
                stats["clouds_s"] = time.perf_counter() - t0
            overlay = over(rgba, overlay)
        return overlay

    def render(self, camera: Any, size: tuple[int, int], full: bool = False) -> NatureFrame:
        """A CPU frame; ``full`` uses the full-resolution terrain, prisms and cloud cells (the reference)."""
        w, h = (int(v) for v in size)
        stats: dict[str, float] = {}
        t0 = time.perf_counter()
        mesh = self.terrain_mesh(camera, (w, h), full)
        if mesh is not None:
            depth, rgb = render_terrain(mesh.points, mesh.triangles, mesh.tcoords, camera, (w, h), self._pyramid)
            stats["terrain_triangles"] = float(mesh.n_triangles)
        else:
            depth, rgb = np.full((h, w), np.inf), np.zeros((h, w, 3), np.float32)
        open_sky = ~np.isfinite(depth)
        base = np.where(open_sky[..., None], render_sky(camera, (w, h), self.sky, mask=open_sky), rgb
                        ).astype(np.float64)
        stats["terrain_s"] = time.perf_counter() - t0
        overlay = self.render_volumes(camera, (w, h), mesh, depth, full, stats)
        final = overlay[..., :3] + (1.0 - overlay[..., 3:4]) * base
        stats["total_s"] = time.perf_counter() - t0
        return NatureFrame(np.clip(final, 0.0, 1.0), overlay, depth, stats, mesh)


# --------------------------------------------------------------------------------------------------- scenes
def demo_scene(seed: int = 0, terrain_size: int = 257, cloud_shape: tuple[int, int, int] = (129, 129, 17)
               ) -> NatureScene:
    """The built-in procedural scene: fractal terrain, Perlin ground fog, Perlin clouds, sky gradient (§10.4, §11.6).

    1000 x 1000 units, relief 160; fog up to 25 units deep in the valleys; a cumulus layer from height 190 to 315.
    """
    # the noise generators (Numba kernels): only for generated scenes
    from volviz.nature import noise

    extent = 1000.0
    h = noise.fractal_terrain(terrain_size, seed=seed + 1, relief=160.0)
    hf = HeightField(h, (extent / (terrain_size - 1),) * 2)
    scene = NatureScene(hf, None, None, big_c=9.0, small_c=40.0)
    fog = noise.fog_map(h, level=55.0, thickness=25.0, seed=seed + 2)
    scene.add_fog("ground_fog", fog, FogLayer(color=(0.85, 0.87, 0.95), density=0.04, mode="attenuated"))
    nx, ny, nz = cloud_shape
    spacing = extent / (nx - 1)
    f = noise.cloud_density(cloud_shape, seed=seed + 3, coverage=0.25)
    g = noise.cloud_light(f, (spacing,) * 3, soft=1.0)
    scene.add_clouds(CloudVolume(f, g, (spacing, extent / (ny - 1), spacing), (0.0, 0.0, 190.0)),
                     CloudShading.npr(rho_max=0.06))
    return scene


def demo_camera(scene: NatureScene | None = None) -> Any:
    return Camera((500.0, -150.0, 330.0), (500.0, 600.0, 80.0), (0.0, 0.0, 1.0), 60.0,
                  clipping_range=(5.0, 10000.0))


# ------------------------------------------------------------------------------------------- session components
def _image_grid(image: Any) -> np.ndarray:
    data = np.asarray(getattr(image, "data", image), dtype=np.float64)
    return grid_from_image(data)


def _dataset(comp: Any, datasets: dict[str, Any]) -> Any:
    if comp.dataset not in datasets:
        raise ValueError(f"component {comp.id!r}: dataset {comp.dataset!r} is not loaded")
    return datasets[comp.dataset]


def _setting_dataset(comp: Any, key: str, datasets: dict[str, Any]) -> Any:
    ref = comp.settings.get(key)
    if ref is None:
        return None
    if ref not in datasets:
        raise ValueError(f"component {comp.id!r}: settings.{key} names dataset {ref!r}, which is not loaded")
    return datasets[ref]


def nature_dataset_ids(components: Sequence[Any]) -> set[str]:
    """Every dataset id a list of nature components needs: their ``dataset`` and any ``settings.*_dataset``."""
    ids: set[str] = set()
    for comp in components:
        if comp.dataset:
            ids.add(comp.dataset)
        for key, value in comp.settings.items():
            if key.endswith("_dataset") and isinstance(value, str):
                ids.add(value)
    return ids


def scene_from_components(components: Sequence[Any], datasets: dict[str, Any]) -> NatureScene:
    """A ``NatureScene`` from session components of types terrain / fog / clouds / sky (in any order).

    terrain: ``dataset`` = height map (PGM or DEM); settings ``extent`` [ex, ey] (default: the image's spacing),
      ``origin`` [x0, y0] (default: the image's),
      ``height_scale`` (1), ``texture_dataset``, ``size`` (2^n + 1), ``C`` (12), ``c`` (60).
    fog: ``dataset`` = thickness map; ``thickness_scale`` (1), ``base_dataset`` + ``base_scale`` + ``base_offset``
      for a cloud layer between two height fields, ``mode`` (attenuated | emissive | mip), ``density``, ``color``,
      ``weight`` (curvature weight, 4).
    clouds: ``dataset`` = a RegularVolume of densities, or generated: ``shape`` [nx, ny, nz], ``seed``,
      ``coverage``; ``base_height``, ``thickness``, ``extent``; ``shading`` (npr | physical), ``rho_max``, ``C``, ``c``.
    sky: ``dataset`` = the polar sky image (optional; default a gradient).
    """
    # the noise generators (Numba kernels) and the sky texture: only for generated parts
    from volviz.nature import noise
    from volviz.nature.sky import sky_texture

    by_type: dict[str, list[Any]] = {}
    for comp in components:
        if getattr(comp, "visible", True):
            by_type.setdefault(comp.type, []).append(comp)
    terrain = None
    texture = None
    settings = TerrainSettings()
    if "terrain" in by_type:
        comp = by_type["terrain"][0]
        settings = validated(TerrainSettings, comp.settings, f"component {comp.id!r} settings")
        if comp.dataset is None:
            h = noise.fractal_terrain(settings.size or 257, seed=settings.seed, relief=settings.relief)
            ext = settings.extent or (1000.0, 1000.0)
            terrain = HeightField(h, (ext[0] / (h.shape[0] - 1), ext[1] / (h.shape[1] - 1)))
        else:
            image = _dataset(comp, datasets)
            terrain = HeightField.from_image(image, settings.extent, settings.height_scale, settings.size)
            if settings.origin is not None:  # e.g. UTM coordinates of a DEM moved to the origin
                terrain = HeightField(terrain.heights, terrain.spacing, settings.origin, terrain.source)
        tex = _setting_dataset(comp, "texture_dataset", datasets)
        if tex is not None:
            texture = np.asarray(tex.data, dtype=np.float32) / float(getattr(tex, "maxval", None) or 255)
    sky = None
    if "sky" in by_type and by_type["sky"][0].dataset:
        sky = sky_texture(_dataset(by_type["sky"][0], datasets))
    scene = NatureScene(terrain, texture, sky, big_c=settings.C, small_c=settings.c)
    for comp in by_type.get("fog", []):
        fog = validated(FogSettings, comp.settings, f"component {comp.id!r} settings")
        if terrain is None:
            raise ValueError(f"component {comp.id!r}: a fog layer needs a terrain component")
        if comp.dataset is None:
            thick = noise.fog_map(terrain.heights, fog.level, fog.thickness, seed=fog.seed)
        else:
            thick = _image_grid(_dataset(comp, datasets)) * fog.thickness_scale
        base_img = _setting_dataset(comp, "base_dataset", datasets)
        base = None
        if base_img is not None:
            base = _image_grid(base_img) * fog.base_scale + fog.base_offset
        layer = FogLayer(color=fog.color, density=fog.density, mode=fog.mode, mip_gain=fog.mip_gain)
        scene.add_fog(comp.id, thick, layer, base, fog.weight)
    for comp in by_type.get("clouds", [])[:1]:
        st = validated(CloudSettings, comp.settings, f"component {comp.id!r} settings")
        if comp.dataset is not None:
            vol = _dataset(comp, datasets)
            dens = np.asarray(vol.data, dtype=np.float64)
            dens = (dens - dens.min()) / max(float(np.ptp(dens)), 1e-12)
        else:
            dens = noise.cloud_density(st.shape, seed=st.seed, coverage=st.coverage)
        ext = st.extent or (terrain.extent if terrain is not None else (1000.0, 1000.0))
        thickness = st.thickness or ext[0] * (dens.shape[2] - 1) / (dens.shape[0] - 1)
        origin = (terrain.origin[0] if terrain else 0.0, terrain.origin[1] if terrain else 0.0, st.base_height)
        spacing = (ext[0] / (dens.shape[0] - 1), ext[1] / (dens.shape[1] - 1), thickness / (dens.shape[2] - 1))
        light = noise.cloud_light(np.ascontiguousarray(dens, dtype=np.float32), spacing, soft=1.0)
        try:
            volume = CloudVolume(dens, light, spacing, origin)
        except ValueError:  # sizes without a common power-of-two cell count: resample (§11.3.1)
            volume = CloudVolume.fit(dens, light, (ext[0], ext[1], thickness), origin)
        shading = CloudShading.physical(st.rho_max) if st.shading == "physical" else CloudShading.npr(st.rho_max)
        scene.add_clouds(volume, shading, st.C, st.c)
    scene.finalize()
    return scene


def _texture_bytes(color_map: np.ndarray) -> np.ndarray:
    """``color_map`` (x, y, RGB in [0, 1]) as a contiguous 8-bit image with row 0 at the largest y."""
    return np.ascontiguousarray(np.clip(color_map.transpose(1, 0, 2)[::-1] * 255.0, 0, 255).astype(np.uint8))
