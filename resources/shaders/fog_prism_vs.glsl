//VTK::System::Dec

// Ground fog / cloud layer prisms (Roettger section 10.3, PCP): each prism is 6 vertices of a static buffer; every
// vertex carries its prism's three vertical side planes, the affine bottom and top heights and the affine bottom and
// top emissions (all relative to the layer's centre). They are the same at the 6 vertices: flat varyings.
in vec4 vertexMC;
in vec3 fogSide0;
in vec3 fogSide1;
in vec3 fogSide2;
in vec3 fogBottom;
in vec3 fogTop;
in vec3 fogEmBottom;
in vec3 fogEmTop;

uniform mat4 MCDCMatrix;

flat out vec3 side0;
flat out vec3 side1;
flat out vec3 side2;
flat out vec3 zBottom;
flat out vec3 zTop;
flat out vec3 eBottom;
flat out vec3 eTop;

void main()
{
  side0 = fogSide0;
  side1 = fogSide1;
  side2 = fogSide2;
  zBottom = fogBottom;
  zTop = fogTop;
  eBottom = fogEmBottom;
  eTop = fogEmTop;
  gl_Position = MCDCMatrix * vertexMC;
}
