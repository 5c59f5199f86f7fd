"""Simulation benchmark: a scripted tour of the office, in sim-seconds per wall-second.

Run: `.venv/bin/python -m bench.sim_bench [--quick]`. Besides the tour it prints what each
adapter call costs next to the bare PyBullet work it wraps, measured in the same run, so the
ratio shows our overhead (noise, bookkeeping, forward kinematics) rather than the machine.
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable

import numpy as np

from sim.robot import Robot
from sim.scene import WORLD_GROUP, load_world

# Waypoints through every room of the office (corridor, kitchen, office1, office2), with a
# look-around stop in each room.
TOUR: list[tuple[str, list[tuple[float, float]]]] = [
    ("kitchen", [(2.0, 3.25), (2.0, 5.0)]),
    ("corridor", [(2.0, 3.25), (7.0, 3.25)]),
    ("office1", [(7.0, 5.0), (7.5, 6.3), (10.5, 6.3)]),
    ("corridor", [(7.5, 6.3), (7.0, 5.0), (7.0, 3.25), (10.0, 3.25)]),
    ("office2", [(10.0, 1.5), (6.0, 1.5)]),
]


def run_tour(seed: int, sense: bool) -> dict[str, float]:
    """Drive the tour once; at each stop look around (scan, 4 detections, depth, place)."""
    with load_world("office", seed=seed) as world:
        robot = world.robot
        start = time.perf_counter()
        visited = set()
        for room, path in TOUR:
            robot.move_along(path)
            visited.add(robot.room())
            assert robot.room() == room, f"tour ended in {robot.room()}, expected {room}"
            if sense:
                _look_around(robot)
        wall = time.perf_counter() - start
        return {"sim": robot.clock, "wall": wall, "metres": robot.odometry,
                "rooms": float(len(visited))}


def _look_around(robot: Robot) -> None:
    robot.scan()
    robot.classify_place()
    for k in range(4):
        robot.turn_to(k * math.pi / 2)
        robot.detect()
    robot.depth()


def _per_call(fn: Callable[[], object], repeats: int) -> float:
    """Mean milliseconds per call of `fn`."""
    start = time.perf_counter()
    for _ in range(repeats):
        fn()
    return (time.perf_counter() - start) * 1000.0 / repeats


def call_costs(repeats: int) -> list[tuple[str, float, str, float]]:
    """(our call, ms, bare PyBullet reference, ms) for the sensing and motion primitives."""
    with load_world("office", seed=0) as world:
        robot, client = world.robot, world.client
        laser = robot.model.laser
        angles = np.linspace(-laser.fov / 2, laser.fov / 2, laser.beams)
        origin = np.array([6.12, 3.2, 0.3])
        ends = origin + laser.max_range * np.column_stack(
            [np.cos(angles), np.sin(angles), np.zeros_like(angles)])
        starts = np.broadcast_to(origin, ends.shape)
        depth_rays = 32 * 24
        d_ends = np.repeat(ends, math.ceil(depth_rays / len(ends)), axis=0)[:depth_rays]
        d_starts = np.broadcast_to(origin, d_ends.shape)
        steps = int(1.0 / 0.05) + 1

        def bare_rays(froms: np.ndarray, tos: np.ndarray) -> Callable[[], object]:
            froms_list, tos_list = froms.tolist(), tos.tolist()
            return lambda: client.rayTestBatch(froms_list, tos_list,
                                               collisionFilterMask=WORLD_GROUP)

        def bare_collisions() -> None:
            for _ in range(steps):
                client.resetBasePositionAndOrientation(robot.body, [6.0, 3.2, 0.0], [0, 0, 0, 1])
                client.performCollisionDetection()
                client.getContactPoints(bodyA=robot.body)

        def move_metre() -> None:
            robot.move_along([(7.0, 3.2)])
            robot.move_along([(6.0, 3.2)])

        return [
            (f"scan() {laser.beams} beams", _per_call(robot.scan, repeats),
             "rayTestBatch same rays", _per_call(bare_rays(starts, ends), repeats)),
            ("depth() 32x24", _per_call(robot.depth, repeats),
             f"rayTestBatch {depth_rays} rays",
             _per_call(bare_rays(d_starts, d_ends), repeats)),
            ("detect() all labels", _per_call(robot.detect, repeats),
             "rayTestBatch 9 rays x 18 things",
             _per_call(bare_rays(starts[:162], ends[:162]), repeats)),
            ("move_along 1 m (x2 legs) / 2", _per_call(move_metre, repeats) / 2,
             f"{steps} bare collision checks", _per_call(bare_collisions, repeats)),
        ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repetitions")
    args = parser.parse_args()
    tours = 1 if args.quick else 5
    repeats = 20 if args.quick else 200
    _print_tours(tours)
    print()
    print(f"{'our call':32} {'ms':>8}   {'bare PyBullet reference':32} {'ms':>8} {'ratio':>6}")
    for ours, ms, ref, ref_ms in call_costs(repeats):
        print(f"{ours:32} {ms:8.3f}   {ref:32} {ref_ms:8.3f} {ms / ref_ms:6.2f}")


def _print_tours(tours: int) -> None:
    print(f"office tour, {tours} run(s) per variant (pioneer, all four rooms)")
    print(f"{'variant':28} {'metres':>7} {'sim s':>8} {'wall s':>8} {'sim s / wall s':>15}")
    rates = {}
    for label, sense in (("motion only (reference)", False), ("motion + look-around", True)):
        runs = [run_tour(seed, sense) for seed in range(tours)]
        sim = float(np.mean([r["sim"] for r in runs]))
        wall = float(np.mean([r["wall"] for r in runs]))
        rates[label] = sim / wall
        print(f"{label:28} {runs[0]['metres']:7.1f} {sim:8.1f} {wall:8.3f} {sim / wall:15.0f}")
    ratio = rates["motion + look-around"] / rates["motion only (reference)"]
    print(f"sensing tour runs at {ratio:.2f}x the sim-rate of the motion-only tour")


if __name__ == "__main__":
    main()
