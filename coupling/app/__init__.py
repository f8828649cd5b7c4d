"""The application: the ``switchsim`` command line, result folders and plots, sweeps, the
accuracy check and the tribometer-fit command. Built on ``coupling.core`` and
``coupling.laws``; nothing there imports this room.
"""
