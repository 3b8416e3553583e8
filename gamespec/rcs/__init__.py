"""Constraint-desensitized planning (thesis §6.4): relevant constraint sensitivity, moving obstacles.

The requested transforms' sections (:mod:`.spec`) and the ``rcs`` / ``moving_obstacles`` transforms
(:mod:`.transform`), their numerics (:mod:`.sensitivity`, :mod:`.relevance`, :mod:`.obstacles`),
figures and summary; the Fig. 6.11 study: its kind (:mod:`.study_spec`), points
(:mod:`.study_points`) and the ``rcs_study`` plugin (:mod:`.multi_obstacle_study`); and the circles of
path constraints drawn in every figure (:mod:`.circles`).
"""
