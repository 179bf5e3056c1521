"""The ``sgc`` console command, the top layer: it drives the baselines on the environments."""
