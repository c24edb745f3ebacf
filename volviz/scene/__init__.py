"""The scene layer: what a file, a folder or a session becomes before anything is drawn (issue #31).

VTK-free and Qt-free: the rules that turn files into a ``volviz.session.Session`` (``opening``: numbered series,
height maps as terrains, PLOT3D pairs, compressed volumes at a level of detail), the demo sessions, reading a
session's datasets once each (``datasets``) and the CPU work a shown component needs that makes no VTK object
(``first_look``, ``isosurfaces``, ``tetra``, ``nature``). ``volviz.render`` builds props and views from these;
``volviz info`` and the readers use them without loading VTK's rendering. The modules are imported one by one (this
package imports none of them), so that a caller loads only what it uses.
"""
