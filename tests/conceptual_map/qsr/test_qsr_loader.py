"""QSR knowledge YAML: the default file loads; bad data fails naming the file and the entry."""

import copy
import math

import pytest
import yaml

from conceptual_map.errors import KnowledgeError
from conceptual_map.qsr import DEFAULT_QSR_PATH, load_qsr, parse_descriptions, parse_qsr

WORLD_TARGETS = ["cup", "keyboard", "laptop", "bottle", "stapler", "whiteboardmarker", "book"]


@pytest.fixture(scope="module")
def data() -> dict:
    return yaml.safe_load(DEFAULT_QSR_PATH.read_text())


def _broken(data: dict, edit) -> dict:
    out = copy.deepcopy(data)
    edit(out)
    return out


def test_default_file_covers_the_built_in_worlds():
    knowledge = load_qsr()
    assert {"monitor", "keyboard", "desk"} <= set(knowledge.fronts)
    for target in WORLD_TARGETS:
        assert knowledge.descriptions_for(target), target
    assert knowledge.relations["right"].mean == pytest.approx(3 * math.pi / 2)
    assert knowledge.fronts["monitor"] == pytest.approx(-math.pi / 2)
    assert all(d.count > 0 for d in knowledge.descriptions)


def test_relations_are_stored_direction_first(data):
    item = {"target": "cup", "relations": ["close", "left"], "of": "keyboard", "count": 1}
    knowledge = parse_descriptions([item], load_qsr())
    assert knowledge.descriptions[0].chain[0].relations == ("left", "close")


@pytest.mark.parametrize(
    ("edit", "entry", "message"),
    [
        (lambda d: d["descriptions"][1].update(relations=["rigth", "close"]),
         "descriptions[1].relations", "unknown relation 'rigth'"),
        (lambda d: d["descriptions"][0].update(of="lamp"),
         "descriptions[0].of", "unknown landmark label 'lamp'"),
        (lambda d: d["descriptions"][3]["via"][0].update(of="sofa"),
         "descriptions[3].via[0].of", "unknown landmark label 'sofa'"),
        (lambda d: d["descriptions"][2].update(count=0), "descriptions[2].count", "> 0"),
        (lambda d: d["descriptions"][2].update(count=-3), "descriptions[2].count", "> 0"),
        (lambda d: d["descriptions"][2].update(count="many"), "descriptions[2].count",
         "finite number"),
        (lambda d: d["descriptions"][2].update(count=True), "descriptions[2].count",
         "finite number"),
        (lambda d: d["descriptions"][2].update(relations=["left", "right"]),
         "descriptions[2].relations", "more than one directional"),
        (lambda d: d["descriptions"][2].update(colour="red"), "descriptions[2]",
         "unknown key(s) colour"),
        (lambda d: d["descriptions"][2].pop("count"), "descriptions[2]", "missing key(s) count"),
        (lambda d: d["descriptions"].append(dict(d["descriptions"][1])), "descriptions[",
         "duplicate description"),
        (lambda d: d["descriptions"][1].update(target="keyboard"), "descriptions[1]",
         "repeats a label"),
        (lambda d: d["relations"].pop("close"), "relations", "missing key(s) close"),
        (lambda d: d["relations"]["left"].update(std_deg=0), "relations.left.std_deg", "> 0"),
        (lambda d: d["landmarks"]["monitor"].update(front_deg="south"),
         "landmarks.monitor.front_deg", "finite number"),
        (lambda d: d["model"].update(samples=1.5), "model.samples", "integer"),
        (lambda d: d["model"].update(default_distance="far"), "model.default_distance", "far"),
    ],
)  # fmt: skip
def test_errors_name_the_entry(data, edit, entry, message):
    with pytest.raises(KnowledgeError) as err:
        parse_qsr(_broken(data, edit), "mine.yaml")
    text = str(err.value)
    assert text.startswith(f"mine.yaml: {entry}"), text
    assert message in text, text


def test_file_errors_name_the_file(tmp_path):
    with pytest.raises(KnowledgeError, match="cannot read"):
        load_qsr(tmp_path / "missing.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("descriptions: [\n")
    with pytest.raises(KnowledgeError, match=r"bad\.yaml: not valid YAML"):
        load_qsr(bad)


def test_user_file_and_task_descriptions(tmp_path, data):
    mine = _broken(data, lambda d: d["relations"]["close"].update(mean=0.2))
    path = tmp_path / "mine.yaml"
    path.write_text(yaml.safe_dump(mine))
    knowledge = load_qsr(path)
    assert knowledge.relations["close"].mean == pytest.approx(0.2)
    task = [{"target": "cup", "relations": ["left"], "of": "keyboard", "count": 1,
             "via": [{"relations": "front", "of": "monitor"}]}]  # fmt: skip
    carried = parse_descriptions(task, knowledge, "task")
    texts = [d.text() for d in carried.descriptions]
    assert texts == ["left(cup, keyboard) & front(keyboard, monitor)"]
    assert carried.relations is knowledge.relations
    with pytest.raises(KnowledgeError, match=r"^task: descriptions\[0\]\.of: unknown landmark"):
        parse_descriptions([{**task[0], "via": [], "of": "mug"}], knowledge, "task")


def test_landmark_pose_turns_yaw_into_the_facing_direction():
    knowledge = load_qsr()
    monitor = knowledge.landmark("monitor", 1.0, 2.0, math.pi / 2, "monitor7")
    assert monitor.facing == pytest.approx(0.0) and monitor.name == "monitor7"
    with pytest.raises(KeyError, match="'cup' is not a landmark label"):
        knowledge.landmark("cup", 0.0, 0.0, 0.0)
