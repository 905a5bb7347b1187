"""The contact planner: guide path -> quasi-static contact plan.

surfaces (support faces of the terrain and sole-in-surface tests), generator (stance,
footholds and the walking loop along the guide).
"""
