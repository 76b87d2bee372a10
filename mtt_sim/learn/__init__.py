"""Learning from the environment: track management as a decision process, and a policy search over it."""
