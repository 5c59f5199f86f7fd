"""Recordings of episodes with Rerun (the optional `viewer` extra: `pip install
avs-planner[viewer]`).

`Recorder` subscribes to an episode's trace events and reads the mind's state when they arrive
(maps, places, rooms and their beliefs, the robot's path, view cones, the DT's belief, the
plan); planners and maps never call it. `open_recording` replays a saved `recording.rrd`.
"""

from __future__ import annotations

from avs_planner.viewer.errors import ViewerError, ViewerMissingError, require_rerun

RECORDING = "recording.rrd"

__all__ = ["RECORDING", "ViewerError", "ViewerMissingError", "require_rerun"]
