"""Build of the optional compiled search core, grounding structure and fixpoints; the project's
metadata is in pyproject.toml."""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "avs_planner.cp._native",
            ["avs_planner/cp/_native.c"],
            depends=["avs_planner/cp/_native_axioms.h"],  # included by _native.c
            # -ffp-contract=off: no fused multiply-add, so every float matches the Python search;
            # -pthread: the second evaluating thread of large searches (SearchOptions.threads)
            extra_compile_args=["-O2", "-std=c11", "-ffp-contract=off", "-pthread"],
            extra_link_args=["-pthread"],
            optional=True,
        ),
        Extension(
            "avs_planner.cp._ground",
            ["avs_planner/cp/_ground.c"],
            extra_compile_args=["-O2", "-std=c11"],
            optional=True,
        ),
        Extension(
            "avs_planner.cp._fixpoint",
            ["avs_planner/cp/_fixpoint.c"],
            extra_compile_args=["-O2", "-std=c11"],
            optional=True,
        ),
    ]
)
