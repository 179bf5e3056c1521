"""Timing benchmarks behind ``sgc bench``: every figure is a ratio against a reference measured
in the same run (a bare PyBullet loop of the same physics, or another checkout), never an
absolute rate alone, so a busy or a slower machine changes the rates but not the verdict."""
