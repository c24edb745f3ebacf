"""Camera paths and fly-through navigation (Qt-free): what the app's fly mode and the movie export share.

A camera path is a list of ``CameraKey(time, CameraState)`` with increasing times. Positions and focal points are
interpolated with centripetal-free uniform Catmull–Rom splines (C1, passes through every key), the view-up vector
linearly and renormalised, angles linearly. Fly navigation moves a camera along its own axes and keeps it above an
optional ground-height function (collision-free flight over terrain).
"""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Callable, Optional, Sequence

import numpy as np

from volviz.model import vec3
from volviz.session import CameraKey, CameraState


def _catmull_rom(p0: np.ndarray, p1: np.ndarray, p2: np.ndarray, p3: np.ndarray, u: float) -> np.ndarray:
    u2, u3 = u * u, u * u * u
    return 0.5 * ((2 * p1) + (-p0 + p2) * u + (2 * p0 - 5 * p1 + 4 * p2 - p3) * u2 + (-p0 + 3 * p1 - 3 * p2 + p3) * u3)


def interpolate_path(keys: Sequence[CameraKey], t: float) -> CameraState:
    """The camera at time ``t`` (clamped to the path's time span)."""
    if not keys:
        raise ValueError("a camera path needs at least one key")
    times = np.array([k.time for k in keys])
    if len(keys) == 1 or t <= times[0]:
        return keys[0].camera
    if t >= times[-1]:
        return keys[-1].camera
    i = int(np.searchsorted(times, t, side="right")) - 1
    u = (t - times[i]) / (times[i + 1] - times[i])
    idx = [max(i - 1, 0), i, i + 1, min(i + 2, len(keys) - 1)]

    def spline(attr: str) -> tuple[float, float, float]:
        p = [np.asarray(getattr(keys[j].camera, attr), dtype=np.float64) for j in idx]
        return vec3(_catmull_rom(p[0], p[1], p[2], p[3], u))

    a, b = keys[i].camera, keys[i + 1].camera
    up = (1 - u) * np.asarray(a.view_up) + u * np.asarray(b.view_up)
    norm = np.linalg.norm(up)
    up = up / norm if norm > 0 else np.asarray(a.view_up)
    position, focal = spline("position"), spline("focal_point")
    if np.allclose(position, focal):
        focal = vec3(np.asarray(position) + (np.asarray(b.focal_point) - np.asarray(b.position)))
    return CameraState(position=position, focal_point=focal, view_up=vec3(up),
                       view_angle=(1 - u) * a.view_angle + u * b.view_angle, parallel=a.parallel,
                       parallel_scale=(1 - u) * a.parallel_scale + u * b.parallel_scale)


def frame_times(keys: Sequence[CameraKey], fps: float, duration: Optional[float] = None) -> np.ndarray:
    """Path times of the movie frames: ``fps`` frames per second of path time, or spread over ``duration`` s."""
    if fps <= 0:
        raise ValueError(f"frames per second must be positive, got {fps}")
    start, end = keys[0].time, keys[-1].time
    seconds = (end - start) if duration is None else float(duration)
    if end <= start or seconds <= 0:
        return np.array([start])
    return np.linspace(start, end, max(int(round(seconds * fps)) + 1, 2))


def orbit_path(center: Sequence[float], radius: float, height: float, keys: int = 9,
               seconds: float = 8.0, view_angle: float = 30.0) -> list[CameraKey]:
    """A closed orbit around ``center`` at ``height`` above it (z up)."""
    c = np.asarray(center, dtype=np.float64)
    out = []
    for i in range(keys):
        a = 2 * math.pi * i / (keys - 1)
        pos = c + np.array([radius * math.cos(a), radius * math.sin(a), height])
        out.append(CameraKey(seconds * i / (keys - 1), CameraState(tuple(pos), tuple(c), (0.0, 0.0, 1.0),
                                                                   view_angle)))
    return out


class FlyNavigator:
    """Fly-through motion: move along the view direction / right / up, and mouse-look (yaw about the up axis,
    pitch about the right axis, pitch limited short of the poles). ``ground(x, y)`` (optional) gives the terrain height
    under a point; the camera is kept ``clearance`` above it. ``obstacle(start, end)`` (optional) gives the distance
    from ``start`` at which the segment to ``end`` first meets opaque geometry (None: free); the camera stops
    ``clearance`` short of it. ``bounds`` (optional) is the box the eye stays in."""

    def __init__(self, speed: float = 1.0, ground: Optional[Callable[[float, float], float]] = None,
                 clearance: float = 0.0, world_up: Sequence[float] = (0.0, 0.0, 1.0),
                 obstacle: Optional[Callable[[np.ndarray, np.ndarray], Optional[float]]] = None):
        self.speed = float(speed)
        self.ground = ground
        self.clearance = float(clearance)
        self.obstacle = obstacle
        self.world_up = np.asarray(world_up, dtype=np.float64) / np.linalg.norm(world_up)
        self.bounds: Optional[tuple[float, ...]] = None   # (xmin, xmax, ymin, ymax, zmin, zmax) the eye stays in

    def _axes(self, cam: CameraState) -> tuple[np.ndarray, np.ndarray, float]:
        pos, focal = np.asarray(cam.position), np.asarray(cam.focal_point)
        forward = focal - pos
        dist = float(np.linalg.norm(forward))
        forward = forward / dist
        right = np.cross(forward, self.world_up)
        if np.linalg.norm(right) < 1e-9:
            right = np.cross(forward, np.asarray(cam.view_up))
        right /= np.linalg.norm(right)
        return forward, right, dist

    def move(self, cam: CameraState, forward: float = 0.0, right: float = 0.0, up: float = 0.0,
             dt: float = 1.0) -> CameraState:
        """Translate camera and focal point together by ``speed * dt`` along the camera's axes."""
        f, r, dist = self._axes(cam)
        delta = self.speed * dt * (forward * f + right * r + up * self.world_up)
        start = np.asarray(cam.position, dtype=np.float64)
        travel = float(np.linalg.norm(delta))
        if self.obstacle is not None and travel > 0:
            direction = delta / travel
            hit = self.obstacle(start, start + direction * (travel + self.clearance))
            if hit is not None:
                delta = direction * max(0.0, min(travel, float(hit) - self.clearance))
        pos = start + delta
        if self.bounds is not None:
            b = self.bounds
            pos = np.clip(pos, [b[0], b[2], b[4]], [b[1], b[3], b[5]])
        if self.ground is not None:
            floor = float(self.ground(pos[0], pos[1])) + self.clearance
            if pos[2] < floor:
                pos[2] = floor
        focal = pos + f * dist
        return replace(cam, position=vec3(pos), focal_point=vec3(focal), view_up=vec3(self.world_up))

    def look(self, cam: CameraState, yaw_degrees: float, pitch_degrees: float) -> CameraState:
        """Turn the view direction: yaw about the world up axis, pitch about the camera's right axis."""
        f, r, dist = self._axes(cam)
        yaw, pitch = math.radians(yaw_degrees), math.radians(pitch_degrees)
        f = _rotate(f, self.world_up, -yaw)
        r = np.cross(f, self.world_up)
        r /= np.linalg.norm(r)
        elevation = math.asin(float(np.clip(np.dot(f, self.world_up), -1, 1)))
        limit = math.radians(85.0)
        pitch = float(np.clip(elevation + pitch, -limit, limit)) - elevation
        f = _rotate(f, r, pitch)
        focal = np.asarray(cam.position) + f * dist
        return replace(cam, focal_point=vec3(focal), view_up=vec3(self.world_up))


def _rotate(v: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation of ``v`` about the unit ``axis``."""
    axis = axis / np.linalg.norm(axis)
    return v * math.cos(angle) + np.cross(axis, v) * math.sin(angle) + axis * np.dot(axis, v) * (1 - math.cos(angle))
