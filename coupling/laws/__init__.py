"""The laws between the domains: tribometer fits (gamma, mu(I), R_c(F_n, I)) and contact
materials (Holm's law), with the data they are fitted to or read from.

Imports nothing of ``coupling.core`` or ``coupling.app``.
"""
