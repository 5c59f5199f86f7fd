"""Experiment campaigns: many episodes over worlds × targets × strategies × robots × seeds.

`campaign.py` reads and expands campaign files; `runner.py` runs the episodes on a backend
(`backends.py`: a local process pool or Ray), resumably, into a results table (`results.py`);
`report.py` turns that table into a Markdown report (its parts: `report_*.py`) with
statistics (`stats.py`) and plots (`plots.py`).
This package calls the episode runner only; it never imports `sim`.
"""

from avs_planner.experiment.campaign import Campaign, RunSpec, load_campaign
from avs_planner.experiment.errors import CampaignError

__all__ = ["Campaign", "CampaignError", "RunSpec", "load_campaign"]
