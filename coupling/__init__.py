"""Co-simulation of mechanics and circuit: scenes, tribometer fits, the `switchsim` command."""
