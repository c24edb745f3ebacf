//VTK::System::Dec

// Projected tetrahedra, pre-integrated (Roettger Ch. 8, digest section 6.4): each tetrahedron is 4 vertices of a
// static buffer; every vertex carries its cell's four face planes, the scalar's affine form and the cell's scalar
// range. They are the same at the 4 vertices, so they are passed as flat varyings (measured on llvmpipe: the draw of
// the Blunt Fin in a 64^2 window took 0.116 s with flat varyings against 0.168 s with smooth ones).
in vec4 vertexMC;
in vec4 ptPlane0;
in vec4 ptPlane1;
in vec4 ptPlane2;
in vec4 ptPlane3;
in vec4 ptScalar;
in vec4 ptRange;
#ifdef PT_SMOOTH
in vec4 ptNormalX;
in vec4 ptNormalY;
in vec4 ptNormalZ;
in vec4 ptBary;
flat out vec4 cellNormalX;
flat out vec4 cellNormalY;
flat out vec4 cellNormalZ;
flat out vec4 cellBary;
#endif

uniform mat4 MCDCMatrix;

//VOLVIZ::include pt_cell_out.glsl

void main()
{
  cellPlane0 = ptPlane0;
  cellPlane1 = ptPlane1;
  cellPlane2 = ptPlane2;
  cellPlane3 = ptPlane3;
  cellScalar = ptScalar;
  cellRange = ptRange;
#ifdef PT_SMOOTH
  cellNormalX = ptNormalX;
  cellNormalY = ptNormalY;
  cellNormalZ = ptNormalZ;
  cellBary = ptBary;
#endif
  gl_Position = MCDCMatrix * vertexMC;
}
