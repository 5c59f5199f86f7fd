"""The head camera: depth rays, and a semantic detector with occlusion, misses and phantoms.

Visibility is decided by ray tests to nine sample points of each object (its centre and its
corners pulled 20% inwards): a point counts when the first surface the ray meets belongs to the
object. An object is reported when enough of its points are visible, then dropped with
probability `fn_rate`; each queried label gets a phantom with probability `fp_rate` (the active
visual search paper by Göbelbecker et al.: 0.2 and 0.05).
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from pybullet_utils.bullet_client import BulletClient

from sim.errors import SimError
from sim.rays import cast_rays, ranges_along
from sim.scene import Detectable
from sim.sensor_data import CameraView, DepthScan, Detection, DetectionFrame

_CORNERS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
_SAMPLE_UNIT = np.vstack([np.zeros((1, 3)), 0.4 * _CORNERS])  # in units of the box size


@dataclass(frozen=True)
class DetectorConfig:
    """Noise model of the semantic camera (model parameters, not measurements)."""

    fn_rate: float = 0.2
    fp_rate: float = 0.05
    min_visible_fraction: float = 0.5
    position_sigma: float = 0.02  # metres per metre of distance (at least this much)

    def __post_init__(self) -> None:
        for name in ("fn_rate", "fp_rate", "min_visible_fraction"):
            value = getattr(self, name)
            if not 0.0 <= value <= 1.0:
                raise SimError(f"DetectorConfig.{name}: must be in [0, 1], got {value}")
        if self.position_sigma < 0:
            raise SimError(f"DetectorConfig.position_sigma: must be >= 0, "
                           f"got {self.position_sigma}")


def view_directions(view: CameraView, columns: int, rows: int) -> np.ndarray:
    """(rows*columns, 3) unit world directions through a pinhole image grid of the view."""
    a = math.tan(view.hfov / 2) * np.linspace(1.0, -1.0, columns)  # left to right
    b = math.tan(view.vfov / 2) * np.linspace(1.0, -1.0, rows)  # top to bottom
    left, up = (m.ravel() for m in np.meshgrid(a, b))
    forward, left_axis, up_axis = _camera_axes(view)
    d = forward[None, :] + left[:, None] * left_axis[None, :] + up[:, None] * up_axis[None, :]
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def depth_frame(client: BulletClient, view: CameraView, size: tuple[int, int], sigma: float,
                rng: np.random.Generator, time: float) -> DepthScan:
    """Depth along a `size` = (columns, rows) grid of rays; misses are np.inf, hits noisy."""
    directions = view_directions(view, *size)
    ranges = ranges_along(client, view.origin, directions, view.max_range)
    hit = np.isfinite(ranges)
    ranges[hit] = np.clip(ranges[hit] + rng.normal(0.0, sigma, hit.sum()), 0.0, view.max_range)
    return DepthScan(origin=view.origin.copy(), directions=directions, ranges=ranges,
                     max_range=view.max_range, time=time, view=view)


def detect_objects(client: BulletClient, view: CameraView, things: Sequence[Detectable],
                   config: DetectorConfig, rng: np.random.Generator, time: float,
                   labels: Sequence[str] | None = None) -> DetectionFrame:
    """Report the visible `things` (of `labels`, or all), with misses and phantoms.

    A frame takes one number from `rng`; each object's miss and noise and each label's
    phantom come from their own stream seeded by it, so what the camera reports of a label
    does not depend on which other labels it was asked for (a strategy that also looks for
    furniture sees the same target detections, frame for frame)."""
    wanted = set(labels) if labels is not None else None
    frame = int(rng.integers(2**63))
    found = []
    for thing in things:
        if wanted is not None and thing.label not in wanted:
            continue
        fraction = visible_fraction(client, view, thing)
        if fraction < max(config.min_visible_fraction, 1e-9):
            continue
        own = _stream(frame, f"object {thing.name}")  # drawn from only for what is in view
        if own.random() < config.fn_rate:
            continue
        found.append(_true_detection(view, thing, fraction, config, own, time))
    vocabulary = sorted({t.label for t in things})
    for label, own in _phantom_labels(labels, vocabulary, config.fp_rate, frame):
        found.append(_phantom(client, view, label, config, own, time))
    queried = tuple(labels) if labels is not None else None
    return DetectionFrame(view=view, detections=tuple(found), time=time, queried=queried)


def sample_points(thing: Detectable) -> np.ndarray:
    """(9, 3) world points on which visibility of `thing` is tested."""
    local = _SAMPLE_UNIT * np.asarray(thing.size)
    c, s = math.cos(thing.yaw), math.sin(thing.yaw)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return np.asarray(thing.center) + local @ rot.T


def visible_fraction(client: BulletClient, view: CameraView, thing: Detectable) -> float:
    """Share of the sample points inside the frustum whose ray reaches `thing` first."""
    points = sample_points(thing)
    inside = view.contains(points)
    if not inside.any():
        return 0.0
    targets = points[inside]
    starts = np.broadcast_to(view.origin, targets.shape)
    fractions, bodies = cast_rays(client, starts, targets)
    reached = (bodies == thing.body) | ((bodies < 0) & (fractions >= 1.0))
    return float(reached.sum()) / len(points)


def _true_detection(view: CameraView, thing: Detectable, fraction: float,
                    config: DetectorConfig, rng: np.random.Generator, time: float) -> Detection:
    center = np.asarray(thing.center, dtype=float)
    distance = float(np.linalg.norm(center - view.origin))
    position = center + rng.normal(0.0, config.position_sigma * max(1.0, distance), 3)
    confidence = float(np.clip(rng.normal(0.55 + 0.4 * fraction, 0.08), 0.05, 0.99))
    return Detection(label=thing.label, position=position, confidence=confidence, time=time,
                     view=view, visible_fraction=fraction, truth_name=thing.name)


def _stream(frame: int, key: str) -> np.random.Generator:
    """The random stream of one object or label in one frame."""
    return np.random.default_rng([frame, zlib.crc32(key.encode())])


def _phantom_labels(labels: Sequence[str] | None, vocabulary: list[str], fp_rate: float,
                    frame: int) -> list[tuple[str, np.random.Generator]]:
    """Per queried label a phantom with probability fp_rate; unqueried: one per call at most.
    Each with the stream its position is drawn from."""
    if labels is not None:
        streams = [(label, _stream(frame, f"phantom {label}")) for label in labels]
        return [(label, own) for label, own in streams if own.random() < fp_rate]
    own = _stream(frame, "phantom")
    if vocabulary and own.random() < fp_rate:
        return [(vocabulary[int(own.integers(len(vocabulary)))], own)]
    return []


def _phantom(client: BulletClient, view: CameraView, label: str, config: DetectorConfig,
             rng: np.random.Generator, time: float) -> Detection:
    """A false positive placed where a random ray through the image meets a surface."""
    forward, left_axis, up_axis = _camera_axes(view)
    a = rng.uniform(-1, 1) * math.tan(view.hfov / 2)
    b = rng.uniform(-1, 1) * math.tan(view.vfov / 2)
    direction = forward + a * left_axis + b * up_axis
    direction /= np.linalg.norm(direction)
    reach = ranges_along(client, view.origin, direction[None, :], view.max_range)[0]
    distance = float(min(reach, view.max_range))
    position = view.origin + direction * distance
    position = position + rng.normal(0.0, config.position_sigma * max(1.0, distance), 3)
    confidence = float(np.clip(rng.normal(0.6, 0.15), 0.05, 0.99))
    return Detection(label=label, position=position, confidence=confidence, time=time,
                     view=view, visible_fraction=0.0, truth_name=None)


def _camera_axes(view: CameraView) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Forward, left and up unit vectors of the camera in the world frame."""
    cy, sy = math.cos(view.yaw), math.sin(view.yaw)
    cp, sp = math.cos(view.pitch), math.sin(view.pitch)
    forward = np.array([cp * cy, cp * sy, sp])
    left = np.array([-sy, cy, 0.0])
    up = np.array([-sp * cy, -sp * sy, cp])
    return forward, left, up
