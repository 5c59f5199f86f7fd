"""HTTP service (FastAPI): tasks, events, plans, domain checks."""
