"""The subcommands of ``sgc``, one module each (see :mod:`baselines.cli.main`)."""
