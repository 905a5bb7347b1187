"""Contact generator (host, Pinocchio Talos): model, equilibrium, leg IK, sample database,
generator, plan format and verifier. Host-only, not jittable. See DESIGN §6."""
