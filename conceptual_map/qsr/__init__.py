"""QSR models for indirect object search (Kunze et al.): qualitative relations to landmarks
become Gaussian mixtures over supporting-plane voxels of the 3D map."""

from conceptual_map.qsr.calculus import Landmark, relative_angle, relative_radius, virtual_robot
from conceptual_map.qsr.errors import QsrError
from conceptual_map.qsr.learning import LearningUpdate, classify, learn_from_observation
from conceptual_map.qsr.loader import (
    DEFAULT_QSR_PATH,
    dump_qsr,
    load_qsr,
    parse_descriptions,
    parse_qsr,
)
from conceptual_map.qsr.mixture import Gaussian2D, GaussianMixture, fit_gaussian
from conceptual_map.qsr.model import (
    DIRECTIONS,
    DISTANCES,
    QsrDescription,
    QsrKnowledge,
    QsrParameters,
    QsrStep,
    RelationModel,
)
from conceptual_map.qsr.planes import PlaneSegment, SupportingPlanes, extract_supporting_planes
from conceptual_map.qsr.sampling import (
    MixtureResult,
    MixtureStatus,
    build_mixture,
    sample_description,
)

__all__ = [
    "DEFAULT_QSR_PATH",
    "DIRECTIONS",
    "DISTANCES",
    "Gaussian2D",
    "GaussianMixture",
    "Landmark",
    "LearningUpdate",
    "MixtureResult",
    "MixtureStatus",
    "PlaneSegment",
    "QsrDescription",
    "QsrError",
    "QsrKnowledge",
    "QsrParameters",
    "QsrStep",
    "RelationModel",
    "SupportingPlanes",
    "build_mixture",
    "classify",
    "dump_qsr",
    "extract_supporting_planes",
    "fit_gaussian",
    "learn_from_observation",
    "load_qsr",
    "parse_descriptions",
    "parse_qsr",
    "relative_angle",
    "relative_radius",
    "sample_description",
    "virtual_robot",
]
