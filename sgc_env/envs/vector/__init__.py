"""The batched env: N sub-envs in shared PyBullet worlds, their task rules run over all of them.

``world`` (worlds shared by sub-envs), ``batch`` (stepping them together), ``task`` (the task's
arrays over sub-envs; every rule it runs is the single env's, called on arrays), ``infos``
(vector and per-sub-env infos from the step's record) and ``vector_env`` (Gymnasium's
``VectorEnv``: every id's vector entry point). Nothing is imported here, so that
``sgc_env.envs.sgc_env`` can import :mod:`.world` without loading the rest.
"""
