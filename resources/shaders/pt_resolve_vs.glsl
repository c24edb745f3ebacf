//VTK::System::Dec

// The GPU PT volume's resolve: the triangle (0, 1, 2) placed over the whole viewport by its vertex index (corners
// (-1, -1), (3, -1), (-1, 3) in normalised device coordinates); vertexMC only gives the actor the volume's bounds, so
// VTK culls it with the cells.
in vec4 vertexMC;

void main()
{
  vec2 corner = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  gl_Position = vec4(corner, 0.0, 1.0);
}
