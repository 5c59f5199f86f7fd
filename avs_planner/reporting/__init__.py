"""Reporting: what is made from an episode's trace for people to read and look at.

`explain.py` (+ `explain_map.py`, `explain_terms.py`, `explain_text.py`): the explanation of a
run; `picture.py`: the trajectory picture; `snapshots.py`: the `map` events viewers draw from.
Nothing here imports the simulator or the harness.
"""
