"""What recording an episode with Rerun costs: the same episodes with and without `record`.

Run: `.venv/bin/python -m bench.viewer_bench [--scenarios a] [--seeds 1-5] [--repeats 1]`
(needs the viewer extra). Each (scenario, seed) runs twice in one process, with and without
recording, in alternating order (with first for odd seeds), after one unmeasured warm-up
episode of each kind (imports, caches, the Rerun SDK's start-up). Wall time is the whole of
`Episode(...).run()` (world set-up, search, summary, explanation, picture; the recording's
set-up and final flush when recording). Printed per episode: both wall times, their ratio, and
the recorder's own time (set-up, every event, the flush: what the recording adds, measured
without the noise of a shared machine); then the medians and the overhead the target bounds
(recording costs <= 10% of an episode's wall time).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from avs_planner.harness import Episode, EpisodeSpec
from avs_planner.harness.scenarios import load_scenario


def one(scenario: str, seed: int, record: bool, out: Path) -> tuple[float, float, int, str]:
    spec = dict(load_scenario(scenario).spec, seed=seed, output_dir=str(out), record=record)
    started = time.perf_counter()
    episode = Episode(EpisodeSpec.from_dict(spec))
    summary = episode.run()
    wall = time.perf_counter() - started
    cost = episode.recorder.cost_s if episode.recorder is not None else 0.0
    size = (out / "recording.rrd").stat().st_size if record else 0
    return wall, cost, size, summary["outcome"]


def seeds(text: str) -> list[int]:
    lo, _, hi = text.partition("-")
    return list(range(int(lo), int(hi or lo) + 1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenarios", default="a")
    parser.add_argument("--seeds", default="1-5", type=seeds)
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        scenario0 = args.scenarios.split(",")[0]
        one(scenario0, 0, True, root / "warm-rec")
        one(scenario0, 0, False, root / "warm-plain")
        print(f"{'run':8s} {'outcome':8s} {'plain s':>8s} {'record s':>9s} {'ratio':>6s} "
              f"{'recorder s':>10s} {'share':>6s} {'rrd kB':>7s}")
        for scenario in args.scenarios.split(","):
            for seed in args.seeds:
                order = (True, False) if seed % 2 else (False, True)
                result = {}
                for record in order:
                    out = root / f"{scenario}{seed}-{int(record)}"
                    result[record] = one(scenario, seed, record, out)
                plain, rec = result[False], result[True]
                share = rec[1] / rec[0]
                rows.append((plain[0], rec[0], rec[1], share))
                print(f"{scenario}/{seed:<6d} {rec[3]:8s} {plain[0]:8.2f} {rec[0]:9.2f} "
                      f"{rec[0] / plain[0]:6.2f} {rec[1]:10.3f} {share:6.1%} {rec[2] / 1e3:7.0f}",
                      flush=True)
    plain = statistics.median(r[0] for r in rows)
    recorded = statistics.median(r[1] for r in rows)
    cost = statistics.median(r[2] for r in rows)
    print(f"median: plain {plain:.2f} s, recording {recorded:.2f} s (x{recorded / plain:.3f}); "
          f"recorder's own time {cost:.3f} s = {statistics.median(r[3] for r in rows):.1%} of "
          f"a recorded episode's wall time (target <= 10%)")


if __name__ == "__main__":
    main()
