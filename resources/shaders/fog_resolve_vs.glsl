//VTK::System::Dec

// The fog layer's resolve: one triangle covering the viewport (its corners in fogCorner, in normalised device
// coordinates); vertexMC only gives the actor the layer's bounds, so VTK culls it with the prisms.
in vec4 vertexMC;
in vec2 fogCorner;

void main()
{
  gl_Position = vec4(fogCorner, 0.0, 1.0);
}
