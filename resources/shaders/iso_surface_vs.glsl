//VTK::System::Dec

// Semi-transparent isosurfaces (libMini note section 4, volviz.render.gl_iso). Every vertex carries its surface's
// style (color, normal-incidence opacity) and iso-spectrum fit (a, b); mu = |n . v| between the unit normal and the
// view ray is computed per vertex and interpolated (perspective-correct), as the CPU rasteriser of
// volviz.iso.composite does. Positions and the eye are relative to the meshes' centre (the actor's position).
in vec4 vertexMC;
in vec3 isoNormal;
in vec4 isoStyle;     // rgb, opacity
in vec2 isoFit;       // spectrum (a, b); a <= 0: constant opacity

uniform mat4 MCDCMatrix;
uniform vec3 isoEye;
uniform vec3 isoForward;
uniform int isoParallel;

out float isoMu;
flat out vec4 styleVSOut;
flat out vec2 fitVSOut;

void main()
{
  vec3 v = isoParallel != 0 ? isoForward : normalize(vertexMC.xyz - isoEye);
  isoMu = abs(dot(isoNormal, v));
  styleVSOut = isoStyle;
  fitVSOut = isoFit;
  gl_Position = MCDCMatrix * vertexMC;
}
