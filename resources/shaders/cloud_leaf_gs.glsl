//VTK::System::Dec
#extension GL_ARB_gpu_shader5 : require

// One C-LOD cloud leaf becomes its 5 tetrahedra (Roettger sections 11.3-11.6; CloudFrame.to_tetmesh's split: the
// central tetrahedron of the corners of the leaf's parity and the 4 corner tetrahedra), one per invocation, in
// back-to-front order for the eye within the leaf (the corner tetrahedra behind the central one, the central one,
// those in front: invocation k makes the k-th, and the primitives of a point's invocations are rasterised in
// invocation order). Per tetrahedron, as gl_pt's cell attributes: the four unit outward face planes (vertices 2 and 3
// swapped where it is negatively oriented), the table field's affine form and range over the cell, and the
// modulating field's affine form (Eq. 11.9), as flat outputs for pt_tet_fs.glsl; its 4 faces as triangles, of which
// front-face culling keeps the back (exit) faces. The leaf's place and its morphed corner values come from
// cloud_leaf_vs.glsl; a leaf whose table field over its corners meets no part of the transfer function with
// extinction (cloudVisible: its closed intervals, volviz.unstructured.topology.visible_ranges) makes nothing. A
// corner's position comes from its grid point alone, so neighbouring leaves share bit-equal vertices (no cracks).
layout(points, invocations = 5) in;
layout(triangle_strip, max_vertices = 12) out;

flat in ivec4 leafPlace[];
flat in vec4 leafTableLow[];
flat in vec4 leafTableHigh[];
flat in vec4 leafModulateLow[];
flat in vec4 leafModulateHigh[];

uniform mat4 MCDCMatrix;
uniform vec2 cloudVisible[8];      // the table field's intervals where the TF has extinction
uniform int cloudVisibleCount;
uniform vec3 cloudOrigin;     // the grid's origin in model coordinates (relative to the actor's position)
uniform vec3 cloudSpacing;
uniform vec3 cloudEye;        // the camera's position in model coordinates

//VOLVIZ::include pt_cell_out.glsl
flat out vec4 cellModulate;

const ivec4 EVEN[5] = ivec4[5](ivec4(0, 6, 5, 3), ivec4(4, 0, 6, 5), ivec4(2, 0, 6, 3), ivec4(1, 0, 5, 3),
                               ivec4(7, 6, 5, 3));
const ivec4 ODD[5] = ivec4[5](ivec4(4, 2, 1, 7), ivec4(0, 4, 2, 1), ivec4(6, 4, 2, 7), ivec4(5, 4, 1, 7),
                              ivec4(3, 2, 1, 7));
const ivec3 FACES[4] = ivec3[4](ivec3(1, 2, 3), ivec3(0, 3, 2), ivec3(0, 1, 3), ivec3(0, 2, 1));

ivec3 cornerBits(int q)
{
  return ivec3((q >> 2) & 1, (q >> 1) & 1, q & 1);
}

float cornerValue(vec4 low, vec4 high, int q)
{
  return q < 4 ? low[q] : high[q - 4];
}

vec4 facePlane(vec3 p0, vec3 p1, vec3 p2)
{
  vec3 n = cross(p1 - p0, p2 - p0);
  float len = length(n);
  if (len > 0.0)
  {
    n /= len;
  }
  return vec4(n, dot(n, p0));
}

// (g, c) with g . x + c = v[i] at the 4 corners p[i] (Cramer's rule: the inverse's columns are the edges' cross
// products over the determinant)
vec4 affineForm(vec3 p[4], vec4 v, vec3 e1, vec3 e2, vec3 e3, float det)
{
  vec3 g = (cross(e2, e3) * (v.y - v.x) + cross(e3, e1) * (v.z - v.x) + cross(e1, e2) * (v.w - v.x)) / det;
  return vec4(g, v.x - dot(g, p[0]));
}

void main()
{
  int s = leafPlace[0].w;
  if (s == 0)
  {
    return;
  }
  vec4 tLow = leafTableLow[0];
  vec4 tHigh = leafTableHigh[0];
  vec4 mLow = leafModulateLow[0];
  vec4 mHigh = leafModulateHigh[0];
  vec4 extremes = max(tLow, tHigh);
  float high = max(max(extremes.x, extremes.y), max(extremes.z, extremes.w));
  extremes = min(tLow, tHigh);
  float low = min(min(extremes.x, extremes.y), min(extremes.z, extremes.w));
  bool shown = false;
  for (int i = 0; i < 8; ++i)
  {
    shown = shown || (i < cloudVisibleCount && high >= cloudVisible[i].x && low <= cloudVisible[i].y);
  }
  if (!shown)
  {
    return;
  }
  ivec3 g0 = leafPlace[0].xyz;
  ivec3 cell = g0 / s;
  bool odd = ((cell.x + cell.y + cell.z) & 1) == 1;
  // the leaf's tetrahedra back to front for the eye: corner tetrahedron t is in front of the central one when the
  // eye is on its side of the plane between them (its corner's L1 distance in leaf units below 1)
  vec3 lowCorner = cloudOrigin + vec3(g0) * cloudSpacing;
  vec3 u = (cloudEye - lowCorner) / (float(s) * cloudSpacing);
  bool front[5];
  front[0] = false;
  for (int t = 1; t < 5; ++t)
  {
    ivec3 b = cornerBits(odd ? ODD[t].x : EVEN[t].x);
    float total = (b.x == 0 ? u.x : 1.0 - u.x) + (b.y == 0 ? u.y : 1.0 - u.y) + (b.z == 0 ? u.z : 1.0 - u.z);
    front[t] = total < 1.0;
  }
  int order[5];
  int k = 0;
  for (int t = 1; t < 5; ++t)
  {
    if (!front[t])
    {
      order[k++] = t;
    }
  }
  order[k++] = 0;
  for (int t = 1; t < 5; ++t)
  {
    if (front[t])
    {
      order[k++] = t;
    }
  }
  int tet = order[gl_InvocationID];
  ivec4 corners = odd ? ODD[tet] : EVEN[tet];
  vec3 p[4];
  vec4 sv;
  vec4 mv;
  for (int v = 0; v < 4; ++v)
  {
    int q = corners[v];
    p[v] = cloudOrigin + vec3(g0 + cornerBits(q) * s) * cloudSpacing;
    sv[v] = cornerValue(tLow, tHigh, q);
    mv[v] = cornerValue(mLow, mHigh, q);
  }
  vec3 e1 = p[1] - p[0];
  vec3 e2 = p[2] - p[0];
  vec3 e3 = p[3] - p[0];
  float det = dot(e1, cross(e2, e3));
  if (det < 0.0)
  {
    vec3 tp = p[2];
    p[2] = p[3];
    p[3] = tp;
    sv.zw = sv.wz;
    mv.zw = mv.wz;
    e2 = p[2] - p[0];
    e3 = p[3] - p[0];
    det = -det;
  }
  vec4 planes[4];
  for (int f = 0; f < 4; ++f)
  {
    planes[f] = facePlane(p[FACES[f].x], p[FACES[f].y], p[FACES[f].z]);
  }
  vec4 scalarForm = affineForm(p, sv, e1, e2, e3, det);
  vec4 range = vec4(min(min(sv.x, sv.y), min(sv.z, sv.w)), max(max(sv.x, sv.y), max(sv.z, sv.w)), 0.0, 0.0);
  vec4 modulateForm = affineForm(p, mv, e1, e2, e3, det);
  for (int f = 0; f < 4; ++f)
  {
    for (int j = 0; j < 3; ++j)
    {
      cellPlane0 = planes[0];
      cellPlane1 = planes[1];
      cellPlane2 = planes[2];
      cellPlane3 = planes[3];
      cellScalar = scalarForm;
      cellRange = range;
      cellModulate = modulateForm;
      gl_Position = MCDCMatrix * vec4(p[FACES[f][j]], 1.0);
      EmitVertex();
    }
    EndPrimitive();
  }
}
