//VTK::System::Dec

// One terrain triangle of a fog or cloud layer becomes its prism (Roettger section 10.3, PCP): the three vertical
// side planes n . (x, y) + d >= 0 (each edge's normal turned towards the opposite vertex), the affine forms
// (gx, gy, c) of the bottom and top heights and of the bottom and top emissions over the triangle (Cramer's rule; its
// doubled area is the determinant), and the prism's 8 triangles wound outward (away from the prism's centroid), all
// carrying these forms as flat outputs for fog_prism_fs.glsl. A prism with no area, no thickness or all six
// emissions <= 0 emits nothing (section 10.3: zero-emission cells are discarded).
layout(triangles) in;
layout(triangle_strip, max_vertices = 24) out;

in vec2 vertexXY[];
in vec4 vertexValue[];

uniform mat4 MCDCMatrix;

flat out vec3 side0;
flat out vec3 side1;
flat out vec3 side2;
flat out vec3 zBottom;
flat out vec3 zTop;
flat out vec3 eBottom;
flat out vec3 eTop;

const ivec3 FACES[8] = ivec3[8](ivec3(0, 2, 1), ivec3(3, 4, 5), ivec3(0, 1, 4), ivec3(0, 4, 3), ivec3(1, 2, 5),
                                ivec3(1, 5, 4), ivec3(2, 0, 3), ivec3(2, 3, 5));

vec3 sidePlane(vec2 a, vec2 b, vec2 c)
{
  vec2 n = vec2(-(b.y - a.y), b.x - a.x);
  if (dot(n, c - a) < 0.0)
  {
    n = -n;
  }
  return vec3(n, -dot(n, a));
}

void main()
{
  vec2 p0 = vertexXY[0];
  vec2 p1 = vertexXY[1];
  vec2 p2 = vertexXY[2];
  vec4 v0 = vertexValue[0];
  vec4 v1 = vertexValue[1];
  vec4 v2 = vertexValue[2];
  vec2 e1 = p1 - p0;
  vec2 e2 = p2 - p0;
  float det = e1.x * e2.y - e2.x * e1.y;
  bool thick = v0.y > v0.x || v1.y > v1.x || v2.y > v2.x;
  bool emits = max(max(max(v0.z, v0.w), max(v1.z, v1.w)), max(v2.z, v2.w)) > 0.0;
  if (det == 0.0 || !thick || !emits)
  {
    return;
  }
  vec3 s0 = sidePlane(p0, p1, p2);
  vec3 s1 = sidePlane(p1, p2, p0);
  vec3 s2 = sidePlane(p2, p0, p1);
  vec3 forms[4];
  for (int f = 0; f < 4; ++f)
  {
    float d1 = v1[f] - v0[f];
    float d2 = v2[f] - v0[f];
    float gx = (d1 * e2.y - d2 * e1.y) / det;
    float gy = (e1.x * d2 - e2.x * d1) / det;
    forms[f] = vec3(gx, gy, v0[f] - gx * p0.x - gy * p0.y);
  }
  vec3 corner[6];
  corner[0] = vec3(p0, v0.x);
  corner[1] = vec3(p1, v1.x);
  corner[2] = vec3(p2, v2.x);
  corner[3] = vec3(p0, v0.y);
  corner[4] = vec3(p1, v1.y);
  corner[5] = vec3(p2, v2.y);
  vec3 mid = (corner[0] + corner[1] + corner[2] + corner[3] + corner[4] + corner[5]) / 6.0;
  for (int f = 0; f < 8; ++f)
  {
    ivec3 t = FACES[f];
    vec3 a = corner[t.x];
    vec3 b = corner[t.y];
    vec3 c = corner[t.z];
    if (dot(cross(b - a, c - a), (a + b + c) / 3.0 - mid) < 0.0)
    {
      vec3 swap = a;
      a = c;
      c = swap;
    }
    vec3 tri[3] = vec3[3](a, b, c);
    for (int j = 0; j < 3; ++j)
    {
      side0 = s0;
      side1 = s1;
      side2 = s2;
      zBottom = forms[0];
      zTop = forms[1];
      eBottom = forms[2];
      eTop = forms[3];
      gl_Position = MCDCMatrix * vec4(tri[j], 1.0);
      EmitVertex();
    }
    EndPrimitive();
  }
}
