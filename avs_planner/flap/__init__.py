"""FLAP view planning (seed 000): frontier view sampling, cell probabilities, expected-time
sequencing. See README.md in this package."""
