"""Build of the optional compiled search core; the project's metadata is in pyproject.toml."""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "avs_planner.cp._native",
            ["avs_planner/cp/_native.c"],
            # -ffp-contract=off: no fused multiply-add, so every float matches the Python search
            extra_compile_args=["-O2", "-std=c11", "-ffp-contract=off"],
            optional=True,
        )
    ]
)
