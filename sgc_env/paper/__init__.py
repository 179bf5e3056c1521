"""The paper's mathematics (Liu, Ko & Chang 1993), below both the env and the baselines.

One course (``course``), routing times (``routing``), the normalized frame S_i and the k rules
of eqs. 12-14 (``frames``), rotation-vector deviations and somersaults (``orientation``), body
plans (``plan``) and the quaternion helpers they share (``quaternion``). Pure numpy/scipy, no
PyBullet. Import the submodules directly: the package itself loads nothing, so that
``import sgc_env`` does not pull in the planner or scipy.
"""
