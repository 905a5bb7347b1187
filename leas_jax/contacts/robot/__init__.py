"""The Talos robot as the contact generator sees it (host, Pinocchio).

model (Talos, constants, quaternion conversion), ik (analytic leg IK), collision
(coal: robot against terrain and itself), equilibrium (hpp-centroidal-dynamics LP and
an independent SciPy LP), database (per-leg sample database).
"""
