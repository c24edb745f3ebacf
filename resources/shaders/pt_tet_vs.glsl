//VTK::System::Dec

// Projected tetrahedra, pre-integrated (Roettger Ch. 8, digest section 6.4): each tetrahedron is 4 vertices of a
// static buffer; every vertex carries its cell's four face planes, the scalar's affine form and the cell's scalar
// range. They are the same at the 4 vertices, so they are passed as flat varyings (measured on llvmpipe: the draw of
// the Blunt Fin in a 64^2 window took 0.116 s with flat varyings against 0.168 s with smooth ones).
//
// PT_ORDER_TEXTURE: the index buffer is static (slot s = vertices 4 s .. 4 s + 3, made once) and the visibility order
// is a texture of cell ids, the only upload per camera: slot s draws the cell ptOrder[s], whose corners and data the
// vertex reads from ptCells (PT_TEXELS texels per cell); slots past ptCount are moved outside the clip volume.
in vec4 vertexMC;
#ifdef PT_ORDER_TEXTURE
uniform sampler2D ptOrder;
uniform int ptOrderWidth;
uniform sampler2D ptCells;
uniform int ptCellsWidth;
uniform int ptCount;
vec4 cellTexel(int i)
{
  return texelFetch(ptCells, ivec2(i % ptCellsWidth, i / ptCellsWidth), 0);
}
#else
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
#endif
#endif
#ifdef PT_SMOOTH
flat out vec4 cellNormalX;
flat out vec4 cellNormalY;
flat out vec4 cellNormalZ;
flat out vec4 cellBary;
#endif

uniform mat4 MCDCMatrix;

//VOLVIZ::include pt_cell_out.glsl

void main()
{
#ifdef PT_ORDER_TEXTURE
  int slot = gl_VertexID / 4;
  if (slot >= ptCount)
  {
    gl_Position = vec4(2.0, 2.0, 2.0, vertexMC.w);   // outside the clip volume: the slot's triangles are dropped
    return;
  }
  int base = PT_TEXELS * int(texelFetch(ptOrder, ivec2(slot % ptOrderWidth, slot / ptOrderWidth), 0).r);
  cellPlane0 = cellTexel(base + 4);
  cellPlane1 = cellTexel(base + 5);
  cellPlane2 = cellTexel(base + 6);
  cellPlane3 = cellTexel(base + 7);
  cellScalar = cellTexel(base + 8);
  cellRange = cellTexel(base + 9);
#ifdef PT_SMOOTH
  cellNormalX = cellTexel(base + 10);
  cellNormalY = cellTexel(base + 11);
  cellNormalZ = cellTexel(base + 12);
  cellBary = cellTexel(base + 13);
#endif
  gl_Position = MCDCMatrix * vec4(cellTexel(base + gl_VertexID - 4 * slot).xyz, 1.0);
#else
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
#endif
}
