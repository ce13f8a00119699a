"""Pictures (matplotlib, the ``plot`` extra, imported inside the functions):

- ``diagram``: the scene diagram (geometry, velocities, delta-V, PDOF, yaw);
  ``inputs`` (scene and result of a call), ``layout`` (where bodies and arrows
  go), ``canvas`` (the drawing surface) and ``labels`` (label placement) serve it;
- ``crash3``: the CRASH3 diagram (crush profiles and PDOFs);
- ``sweep``: heat maps and lines of a parameter sweep;
- ``argument``: the ``--plot PATH`` option of the CLI.

The public face is :mod:`impactsym.plot`.
"""
