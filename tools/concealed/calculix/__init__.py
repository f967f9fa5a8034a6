"""Helpers of tools/concealed/calculix_world.py: meshing (gmsh), CalculiX input/output, and the
transfer of a fine quadratic CalculiX solution onto a coarse linear tetrahedral mesh."""
