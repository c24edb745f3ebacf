//VTK::System::Dec

// Ground fog / cloud layer prisms (Roettger section 10.3, PCP): the vertices of the layer's terrain triangles. Each
// carries its xy (relative to the layer's centre) in vertexMC and its bottom and top heights (relative to the centre)
// and bottom and top emissions in fogValue; fog_prism_gs.glsl makes each triangle's prism.
in vec4 vertexMC;
in vec4 fogValue;

out vec2 vertexXY;
out vec4 vertexValue;

void main()
{
  vertexXY = vertexMC.xy;
  vertexValue = fogValue;
  gl_Position = vertexMC;
}
