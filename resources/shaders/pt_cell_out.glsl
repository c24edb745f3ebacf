// A tetrahedron's cell data, the same at its 4 vertices: flat varyings for pt_tet_fs.glsl (the four face planes,
// the scalar's affine form, the cell's scalar range).
flat out vec4 cellPlane0;
flat out vec4 cellPlane1;
flat out vec4 cellPlane2;
flat out vec4 cellPlane3;
flat out vec4 cellScalar;
flat out vec4 cellRange;
