"""bendlab: membrane bending forces on triangulated surfaces, and capsules in flow.

The six bending algorithms of Guckenberger et al. (2016), "On the bending algorithms for soft
objects in flows" -- A (Kantor-Nelson, eq. 6), B (Gompper-Kroll, eqs. 7-9), C (Meyer, eqs. 10-12),
D (Belkin, eq. 13), E (Farutin), their mix ED and S (Loop subdivision shell) -- behind one class,
`Method`, with numpy arrays in and out. Signs and units: docs/conventions.md.

    import bendlab
    mesh = bendlab.sphere_mesh("mt1", level=3)                # 1280 triangles
    rbc = bendlab.surface("rbc")
    mesh = mesh.with_positions(rbc.map_from_unit_sphere(mesh.vertices))
    r = bendlab.Method("C").compute(mesh, kappa_b=1.0)
    r.H, r.force_density, r.force                             # numpy views, no copies

Library errors (a mesh that is not closed, a bad option, wrong array shapes or dtypes, NaN) raise
ValueError with the library's one-line message.
"""
from ._bendlab import *  # noqa: F401,F403
from ._bendlab import __doc__ as _module_doc  # noqa: F401

__version__ = "0.1.0"
