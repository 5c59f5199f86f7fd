"""Sampling relations, the 2D Gaussian fit and the count-weighted mixture."""

import math

import numpy as np
import pytest

from bench import qsr_scene
from conceptual_map.qsr import (
    Gaussian2D,
    GaussianMixture,
    MixtureStatus,
    QsrError,
    build_mixture,
    fit_gaussian,
    load_qsr,
    relative_angle,
    sample_description,
    virtual_robot,
)


def test_fit_recovers_known_mean_and_covariance():
    rng = np.random.default_rng(0)
    mean, cov = np.array([2.0, -1.0]), np.array([[0.04, 0.015], [0.015, 0.09]])
    fit = fit_gaussian(rng.multivariate_normal(mean, cov, 20000))
    np.testing.assert_allclose(fit.mean, mean, atol=0.01)
    np.testing.assert_allclose(fit.cov, cov, atol=0.004)


def test_fit_needs_two_2d_samples():
    with pytest.raises(QsrError, match="at least two"):
        fit_gaussian(np.zeros((1, 2)))


def test_mixture_weights_follow_counts_and_density_is_normalised():
    a = Gaussian2D(np.array([0.0, 0.0]), np.diag([0.01, 0.02]))
    b = Gaussian2D(np.array([1.0, 0.5]), np.array([[0.03, 0.01], [0.01, 0.02]]))
    mix = GaussianMixture.from_weighted([(3.0, a, "a"), (1.0, b, "b")])
    np.testing.assert_allclose(mix.weights, [0.75, 0.25])
    xs, ys = np.meshgrid(np.linspace(-1, 2, 301), np.linspace(-1, 1.5, 251), indexing="ij")
    grid = np.column_stack([xs.ravel(), ys.ravel()])
    assert mix.pdf(grid).sum() * 0.01 * 0.01 == pytest.approx(1.0, abs=1e-3)
    some = grid[::997]
    np.testing.assert_allclose(mix.pdf(some), 0.75 * a.pdf(some) + 0.25 * b.pdf(some))


def test_mixture_samples_refit_to_its_components():
    truth = [Gaussian2D(np.array([0.0, 0.0]), np.diag([0.01, 0.04])),
             Gaussian2D(np.array([3.0, 1.0]), np.diag([0.02, 0.01]))]  # fmt: skip
    mix = GaussianMixture.from_weighted([(2.0, truth[0], "a"), (6.0, truth[1], "b")])
    points = mix.sample(40000, np.random.default_rng(1))
    right = points[:, 0] > 1.5
    assert right.mean() == pytest.approx(0.75, abs=0.01)
    for g, part in zip(truth, (points[~right], points[right]), strict=True):
        fit = fit_gaussian(part)
        np.testing.assert_allclose(fit.mean, g.mean, atol=0.01)
        np.testing.assert_allclose(fit.cov, g.cov, atol=0.003)


def test_samples_of_one_relation_follow_its_gaussians_through_eq_1():
    knowledge = load_qsr()
    right = next(d for d in knowledge.descriptions_for("cup") if len(d.chain) == 1
                 and d.chain[0].relations == ("right", "close"))  # fmt: skip
    keyboard = knowledge.landmark("keyboard", 1.5, 5.35, 0.0)
    points = sample_description(right, keyboard, knowledge, 20000, np.random.default_rng(2))
    phi = relative_angle(virtual_robot(keyboard, 1.0), keyboard.xy, points)
    assert np.mean(phi) == pytest.approx(3 * math.pi / 2, abs=0.01)
    assert np.std(phi) == pytest.approx(math.radians(20), abs=0.01)
    dist = np.linalg.norm(points - keyboard.xy, axis=1)
    assert dist.mean() == pytest.approx(0.35, abs=0.005)
    assert dist.std() == pytest.approx(0.08, abs=0.005)
    assert np.mean(points[:, 0]) > 1.5 + 0.25  # right of the keyboard is +x on this desk


def test_chained_description_goes_through_the_hallucinated_keyboard():
    knowledge = load_qsr()
    chain = next(d for d in knowledge.descriptions_for("cup") if len(d.chain) == 2
                 and d.chain[0].relations[0] == "right")  # fmt: skip
    monitor = knowledge.landmark("monitor", 1.5, 5.7, 0.0)
    points = sample_description(chain, monitor, knowledge, 20000, np.random.default_rng(4))
    # keyboards ~0.35 in front (-y) of the monitor, cups ~0.35 to their right (+x)
    np.testing.assert_allclose(points.mean(axis=0), [1.5 + 0.33, 5.7 - 0.33], atol=0.03)
    one_step = next(d for d in knowledge.descriptions_for("cup") if len(d.chain) == 1
                    and d.chain[0].relations[0] == "right")  # fmt: skip
    keyboard = knowledge.landmark("keyboard", 1.5, 5.35, 0.0)
    direct = sample_description(one_step, keyboard, knowledge, 20000, np.random.default_rng(5))
    # two steps of noise spread wider than one
    assert np.cov(points, rowvar=False).trace() > 1.5 * np.cov(direct, rowvar=False).trace()


def test_build_mixture_splits_counts_between_landmark_instances():
    knowledge = load_qsr()
    result = build_mixture(knowledge, "cup", qsr_scene.landmarks(knowledge), rng=0, samples=200)
    assert result.status is MixtureStatus.BUILT and result.built
    counts = {d.text(): d.count for d in knowledge.descriptions_for("cup")}
    total = sum(counts.values())
    for weight, source in zip(result.mixture.weights, result.mixture.sources, strict=True):
        text = source.split(" [")[0]
        assert weight == pytest.approx(counts[text] / 4 / total)  # four desks of each landmark
    assert len(result.samples) == len(result.mixture)
    # the densest spot is beside a keyboard, where the scene's cups are
    poses = qsr_scene.object_poses()
    cups = np.array([poses[c][1:3] for c in ("cup1", "cup3")])
    empty = np.array([[4.0, 3.0], [1.5, 5.7]])  # the room's middle, a monitor's foot
    assert result.mixture.pdf(cups).min() > 20 * result.mixture.pdf(empty).max()


def test_build_mixture_statuses():
    knowledge = load_qsr()
    assert build_mixture(knowledge, "unicorn", []).status is MixtureStatus.NO_DESCRIPTIONS
    only_desks = [knowledge.landmark("table", 0, 0, 0)]
    result = build_mixture(knowledge, "keyboard", only_desks)
    assert result.status is MixtureStatus.NO_LANDMARKS and result.mixture is None
