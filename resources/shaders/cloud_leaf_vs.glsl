//VTK::System::Dec

// C-LOD cloud leaves on the projected-tetrahedra pass (Roettger sections 11.3-11.6): one point per leaf, drawn in
// the leaves' back-to-front order (the index buffer holds the leaves' numbers); cloud_leaf_gs.glsl makes each leaf's
// 5 tetrahedra from its texels.
in vec4 vertexMC;

flat out int leafId;

void main()
{
  leafId = gl_VertexID;
  gl_Position = vertexMC;
}
