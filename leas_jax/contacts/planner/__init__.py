"""The contact planner: guide path -> quasi-static contact plan.

generator (ContactGenerator, plan_contacts: the stages in order), and its stages:
stance (initial double support), walking (keep both contacts or step, pose after pose),
footholds (ranked sole placements from the leg databases on the support faces),
projection (a root pose and contacts -> a checked posture); config (GeneratorConfig);
surfaces (support faces of the terrain and sole-in-surface tests).
"""
