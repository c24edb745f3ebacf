//VTK::System::Dec

// C-LOD cloud tetrahedra on the projected-tetrahedra pass (Roettger sections 11.3-11.6 drawn as pt_tet_vs.glsl
// draws a mesh): the vertex buffer holds only the positions, 4 per tetrahedron (tetrahedron t's at 4 t ... 4 t + 3);
// each tetrahedron's cell data, 7 RGBA float texels from texel 7 t of the buffer texture cloudCells, is fetched by
// gl_VertexID / 4 (the index buffer sets the back-to-front order, not the vertices' place): the four face planes,
// the table field's affine form, its range over the cell, and the modulating field's affine form (Eq. 11.9).
in vec4 vertexMC;

uniform mat4 MCDCMatrix;
uniform samplerBuffer cloudCells;

//VOLVIZ::include pt_cell_out.glsl
flat out vec4 cellModulate;

void main()
{
  int base = (gl_VertexID / 4) * 7;
  cellPlane0 = texelFetch(cloudCells, base);
  cellPlane1 = texelFetch(cloudCells, base + 1);
  cellPlane2 = texelFetch(cloudCells, base + 2);
  cellPlane3 = texelFetch(cloudCells, base + 3);
  cellScalar = texelFetch(cloudCells, base + 4);
  cellRange = texelFetch(cloudCells, base + 5);
  cellModulate = texelFetch(cloudCells, base + 6);
  gl_Position = MCDCMatrix * vertexMC;
}
