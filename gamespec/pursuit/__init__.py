"""Pursuit-evasion with several pursuers and one evader (thesis ch. 2 and §3.2).

Geometry and closed forms (:mod:`regions`, :mod:`constant_bearing`, :mod:`pure_pursuit`,
:mod:`relay`), the true dynamics (:mod:`simulation`), the reduced-state problems the ``engagement``
kind generates (:mod:`reduced`), what a solution reports (:mod:`report`), MPSE capturing sets
(:mod:`mpse`), the ``analytic`` backend and plots (the Table 2.1 study is in
:mod:`gamespec.suboptimal_study`).
"""
