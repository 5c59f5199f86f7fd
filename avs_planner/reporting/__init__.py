"""Reporting: what is made from an episode's trace for people to read and look at.

`explain.py`: the explanation of a run, made by `explain_ledger.py` (the assumption ledger over
the trace), `explain_document.py` (what it says, as data), `explain_beliefs.py` (the mind's
final beliefs), `explain_files.py` (run folders on disk), `explain_text.py` (as text), with
`explain_terms.py` and `explain_map.py`; `picture.py`: the trajectory picture;
`snapshots.py`: the `map` events viewers draw from.
Nothing here imports the simulator or the harness.
"""
