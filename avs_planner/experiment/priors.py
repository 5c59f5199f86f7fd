"""Campaigns with the experience store (learned priors): training runs that write it, test arms
that read it.

A campaign's `experience` key (docs/experiments.md, "Learned priors"):

- `experience: {learn: true}` (training): every episode gets `experience: <store>` and
  `building: <world name>`, and adds what it found to the store when it ends (the store's
  SQLite transactions let several workers write to one file). `store` defaults to
  `experience.sqlite3` in the campaign's output directory.
- `experience: {store: PATH, learn: false}` with `priors: [default, learned]` (testing): the
  `learned` arm's episodes read the store and never write it (episode spec `learn: false`);
  the `default` arm's run without a store, on the knowledge file alone. Without `priors`,
  every episode is a `learned` one.

A relative `store` is taken relative to the campaign's output directory (so the built-in test
campaigns name `../priors-train/experience.sqlite3`: the training campaign's output beside
theirs); `avs experiment run --experience PATH` replaces it for every episode that has one.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from avs_planner.experiment.errors import CampaignError
from avs_planner.experiment.values import Where

STORE_FILE = "experience.sqlite3"  # a training campaign's store, in its output directory
PRIORS_ARMS = ("default", "learned")
EXPERIENCE_KEYS = ("learn", "store")


@dataclass(frozen=True)
class Experience:
    """A campaign's use of the experience store: whether its episodes write to it, and where
    it is (as written: relative to the output directory unless absolute)."""

    learn: bool
    store: str = STORE_FILE

    def episode_keys(self, building: str) -> dict[str, Any]:
        """What an episode that uses the store says in its spec."""
        keys: dict[str, Any] = {"experience": self.store, "building": building}
        if not self.learn:
            keys["learn"] = False
        return keys


def parse_experience(value: Any, where: Where) -> Experience:
    """`{learn: true|false, store: PATH}` (store required with learn: false)."""
    if not isinstance(value, dict):
        raise where.error("a mapping {learn: true} (training: write the store) or {store: "
                          "PATH, learn: false} (testing: read it)")
    unknown = set(value) - set(EXPERIENCE_KEYS)
    if unknown:
        raise where.error(f"unknown keys {sorted(unknown)}; allowed: {list(EXPERIENCE_KEYS)}")
    if "learn" not in value or not isinstance(value["learn"], bool):
        raise where.at("learn").error(f"true (episodes add what they find to the store) or "
                                      f"false (they only read it); got "
                                      f"{value.get('learn')!r}")
    store = value.get("store")
    if store is not None and (not isinstance(store, str) or not store.strip()):
        raise where.at("store").error(f"the path of an experience store file, got {store!r}")
    if store is None and not value["learn"]:
        raise where.at("store").error("learn: false reads a store: give its path (relative "
                                      "to the campaign's output directory, or absolute)")
    return Experience(value["learn"], store or STORE_FILE)


def parse_priors(value: Any, experience: Experience | None, where: Where,
                 experience_at: Where) -> tuple[str, ...]:
    """`priors: [default, learned]`: the arms, each once; `learned` needs a store read
    without learning (the arms must not change what the other reads)."""
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not value:
        raise where.error(f"a non-empty list of arms: {', '.join(PRIORS_ARMS)}")
    for i, arm in enumerate(value):
        if arm not in PRIORS_ARMS:
            raise where.at(i).error(f"unknown arm {arm!r}; the arms are "
                                    f"{', '.join(PRIORS_ARMS)}")
        if arm in value[:i]:
            raise where.at(i).error(f"arm {arm!r} is listed twice")
    if "learned" in value:
        if experience is None:
            raise where.error("the learned arm reads an experience store: give "
                              "'experience: {store: PATH, learn: false}'")
        if experience.learn:
            raise experience_at.at("learn").error(
                "false with 'priors': the arms are measured on a store that does not change "
                "while they run (train it with a campaign of its own, learn: true)")
    return tuple(value)


def placed_store(episode: dict[str, Any], out: Path, override: Path | None = None
                 ) -> dict[str, Any]:
    """The episode spec with its store's path made absolute: `override` when given, else
    the spec's path under the output directory `out` (unless absolute)."""
    store = episode.get("experience")
    if store is None:
        return episode
    path = override if override is not None else Path(store)
    if override is None and not path.is_absolute():
        path = out / path
    return {**episode, "experience": str(path.resolve())}


def prepare_stores(episodes: list[dict[str, Any]]) -> None:
    """Before any episode runs: make each store that episodes will write (so that no two
    workers make the same new file at once), and check that each store read without
    learning exists; CampaignError naming the file otherwise."""
    from conceptual_map.errors import ExperienceError
    from conceptual_map.knowledge.experience import ExperienceStore

    writes = {e["experience"] for e in episodes if e.get("experience") and e.get("learn", True)}
    reads = {e["experience"] for e in episodes if e.get("experience")} - writes
    for path in sorted(writes):
        try:
            Path(path).parent.mkdir(parents=True, exist_ok=True)
            ExperienceStore(path).close()
        except (OSError, ExperienceError) as exc:
            raise CampaignError(f"experience store {path}: {exc}") from None
    for path in sorted(reads):
        try:
            ExperienceStore(path, readonly=True).close()
        except ExperienceError as exc:
            raise CampaignError(f"experience store {path}: {exc} (run the training campaign "
                                f"first, or give --experience PATH)") from None
