"""Mapping benchmark: ray integration rates of the 2D grid and 3D voxels, and an office run.

Run: `.venv/bin/python -m bench.maps_bench [--quick]`. Each vectorised rate is printed next to
a straightforward per-ray Python integration (the textbook cell walk, one log-odds update per
cell) measured in the same run on the same rays, so the ratio does not depend on the machine.
The office run explores the simulator's `office` world by nearest placeholder and reports the
time spent in the robot's maps (grid + place map) per scan.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from conceptual_map.metric import OccupancyGrid, VoxelMap
from conceptual_map.metric.logodds import LogOddsGrid, SensorModel
from conceptual_map.metric.raycast import traverse_reference
from conceptual_map.metric.sensors import Rays, depth_rays, laser_rays
from conceptual_map.metric.synthetic import BoxWorld, rooms_world

OFFICE_ROOMS = [(0.0, 2.5, 12.0, 4.0), (0.0, 4.0, 4.5, 8.0), (4.5, 4.0, 12.0, 8.0),
                (4.0, 0.0, 12.0, 2.5)]  # fmt: skip
OFFICE_DOORS = [(2.0, 4.0, 0.9), (7.0, 4.0, 0.9), (10.0, 2.5, 0.9)]


def reference_integrate(grid: LogOddsGrid, rays: Rays) -> None:
    """Per ray: walk its cells in Python, lower free cells, raise the hit cell."""
    m: SensorModel = grid.model
    scale = 1.0 / grid.resolution
    shape = grid.shape
    values = grid.logodds
    for start, end, hit in zip(rays.starts, rays.ends, rays.hit, strict=True):
        cells = traverse_reference((start - grid.origin) * scale, (end - grid.origin) * scale)
        last = len(cells) - 1
        for k, cell in enumerate(cells):
            if not all(0 <= c < n for c, n in zip(cell, shape, strict=True)):
                continue
            step = m.hit if (hit and k == last) else m.miss
            values[cell] = min(max(int(values[cell]) + step, m.clamp_min), m.clamp_max)


def rate(fn, batches: list, rays_per_batch: list[int], min_time: float) -> float:  # noqa: ANN001
    """Rays per second of `fn` over the batches, repeated until `min_time` has passed."""
    done, began = 0, time.perf_counter()
    while True:
        for batch, n in zip(batches, rays_per_batch, strict=True):
            fn(batch)
            done += n
        elapsed = time.perf_counter() - began
        if elapsed >= min_time:
            return done / elapsed


def laser_batches(world: BoxWorld, beams: int, count: int) -> list:
    rng = np.random.default_rng(0)
    poses = [
        (rng.uniform(0.5, 11.5), rng.uniform(2.8, 3.7), rng.uniform(-3, 3)) for _ in range(count)
    ]
    return [world.laser(p, beams=beams, fov=np.radians(240), max_range=5.6) for p in poses]


def depth_batches(world: BoxWorld, size: tuple[int, int], count: int) -> list:
    rng = np.random.default_rng(1)
    eyes = [(rng.uniform(1, 11), rng.uniform(2.8, 3.7), 1.4) for _ in range(count)]
    return [world.depth(e, rng.uniform(-3, 3), -0.3, size=size, max_range=4.5) for e in eyes]


def bench_laser(world: BoxWorld, beams: int, quick: bool) -> tuple[float, float]:
    scans = laser_batches(world, beams, 10)
    sizes = [len(s.ranges) for s in scans]
    grid = OccupancyGrid(origin=(-1, -1), size=(14, 10))
    vec = rate(grid.integrate_scan, scans, sizes, 0.5 if quick else 2.0)
    ref_grid = OccupancyGrid(origin=(-1, -1), size=(14, 10))
    ref = rate(
        lambda s: reference_integrate(ref_grid, laser_rays(s)),
        scans[:3],
        sizes[:3],
        0.5 if quick else 2.0,
    )
    return vec, ref


def bench_depth(world: BoxWorld, size: tuple[int, int], quick: bool) -> tuple[float, float, float]:
    frames = depth_batches(world, size, 6)
    sizes = [len(f.ranges) for f in frames]
    voxels = VoxelMap(origin=(-0.5, -0.5, 0.0), size=(13.0, 9.0, 2.0))
    vec = rate(voxels.integrate_depth, frames, sizes, 0.5 if quick else 2.0)
    ref_map = VoxelMap(origin=(-0.5, -0.5, 0.0), size=(13.0, 9.0, 2.0))
    ref = rate(
        lambda f: reference_integrate(ref_map, depth_rays(f)),
        frames[:1],
        sizes[:1],
        0.5 if quick else 2.0,
    )
    began = time.perf_counter()
    voxels.compute_frontier()
    full = time.perf_counter() - began
    return vec, ref, full


def office_run() -> dict[str, float] | None:
    try:
        import sim
    except ImportError:
        return None
    from conceptual_map.places import PlaceMap, PlaceMapConfig
    from conceptual_map.places.exploration import Explorer

    with sim.load_world("office", seed=1) as world:
        grid, place_map = OccupancyGrid(), PlaceMap(PlaceMapConfig(robot_radius=0.3))
        began = time.perf_counter()
        result = Explorer(world.robot, grid, place_map).run()
        wall = time.perf_counter() - began
    return {
        "status": result.status.value, "scans": result.scans, "moves": result.moves,
        "distance_m": result.distance, "sim_s": result.sim_time, "wall_s": wall,
        "mapping_s": result.mapping_wall_time, "mapping_cpu_s": result.mapping_cpu_time,
        "rooms": len(place_map.rooms),
        "doors": len(place_map.doors), "places": len(place_map.places),
    }  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="short timings, no office run")
    args = parser.parse_args()
    world = rooms_world(OFFICE_ROOMS, OFFICE_DOORS)
    world.add_box(1.4, 5.6, 2.6, 6.4, 0.0, 0.75)  # a table, so depth rays hit furniture too
    print("ray integration (rays/s): vectorised vs per-ray Python reference, same rays")
    print(f"{'what':34s} {'vectorised':>12s} {'reference':>12s} {'ratio':>8s}")
    for beams in (241, 1081):
        vec, ref = bench_laser(world, beams, args.quick)
        label = f"2D laser scan, {beams} beams, 5.6 m"
        print(f"{label:34s} {vec:12,.0f} {ref:12,.0f} {vec / ref:7.1f}x")
    for size in [(32, 24), (64, 48)]:
        vec, ref, full = bench_depth(world, size, args.quick)
        label = f"3D depth {size[0]}x{size[1]}, 4.5 m (+frontier)"
        print(f"{label:34s} {vec:12,.0f} {ref:12,.0f} {vec / ref:7.1f}x")
    print(
        f"full frontier recompute of a 13x9x2 m map: {full * 1000:.1f} ms "
        "(the incremental update is part of the 3D rate above)"
    )
    if args.quick:
        return
    office = office_run()
    if office is None:
        print("office exploration: skipped (sim not importable)")
        return
    per_scan = office["mapping_s"] / max(office["scans"], 1) * 1000
    per_scan_cpu = office["mapping_cpu_s"] / max(office["scans"], 1) * 1000
    print(
        f"office exploration ({office['status']}): {office['scans']} scans, "
        f"{office['moves']} moves, {office['distance_m']:.1f} m, {office['sim_s']:.0f} sim-s, "
        f"{office['wall_s']:.1f} wall-s of which maps {office['mapping_s']:.1f} s "
        f"({per_scan:.0f} ms wall, {per_scan_cpu:.0f} ms CPU per scan: grid + place map); "
        f"found {office['rooms']} rooms, "
        f"{office['doors']} doors, {office['places']} places"
    )


if __name__ == "__main__":
    main()
