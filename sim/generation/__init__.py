"""Parts of the floor-plan generator (`sim.generate`): placement table, layout, furnishing.

`sim.generate.generate_world` is the entry point; these modules each hold one step.
"""
