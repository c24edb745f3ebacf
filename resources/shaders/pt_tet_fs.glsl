//VTK::System::Dec

// Pre-integrated projected tetrahedra, one fragment of a cell's back (exit) face (Roettger section 8.4, digest 6.4;
// the separable lookup: Ch. 9, section 9.1, digest 7.1-7.2).
//
// The pixel ray O + t D (D . forward = 1, so t is the depth along the direction of projection) is rebuilt from
// gl_FragCoord with the camera's affine ray basis, exactly as the CPU renderer's rays. The segment inside the cell
// is the ray clipped against the cell's four face planes (n . x <= d inside), the user's clipping planes, the near
// plane, the far plane and the opaque scene's depth at this pixel. The scalar is affine in the cell,
// s(x) = g . x + c, clamped to the cell's vertex range at both ends. The pre-integrated RGBA of (s_f, s_b, length)
// comes from the table; the output is premultiplied, composited back to front with (ONE, ONE_MINUS_SRC_ALPHA).

flat in vec4 cellPlane0;
flat in vec4 cellPlane1;
flat in vec4 cellPlane2;
flat in vec4 cellPlane3;
flat in vec4 cellScalar;
flat in vec4 cellRange;

uniform vec3 rayO0;
uniform vec3 rayOx;
uniform vec3 rayOy;
uniform vec3 rayD0;
uniform vec3 rayDx;
uniform vec3 rayDy;
uniform float viewHeight;
uniform vec2 clipRange;
uniform int parallelView;
uniform int useDepth;
uniform sampler2D opaqueDepth;

uniform int clipCount;       // user clipping planes (n, d), n . x <= d kept, relative to the mesh centre
uniform vec4 clipPlanes[8];

uniform int lookupKind;      // 0: 3D table, 1: separable table
uniform sampler3D ptTable;
uniform vec4 tableAxis;      // s_lo, 1 / ds, n_s, 0
uniform vec4 tableLength;    // 1 / dl (3D) or 1 / l_max (separable), n_l, degree, 0
uniform vec3 kappaMax;

//VTK::Output::Dec

void clipPlane(vec4 plane, vec3 o, vec3 d, inout float t0, inout float t1)
{
  float a = dot(plane.xyz, o) - plane.w;
  float b = dot(plane.xyz, d);
  if (b > 0.0)
  {
    t1 = min(t1, -a / b);
  }
  else if (b < 0.0)
  {
    t0 = max(t0, -a / b);
  }
  else if (a > 0.0)
  {
    t1 = -1.0e30;
  }
}

float opaqueLimit()
{
  float z = texelFetch(opaqueDepth, ivec2(gl_FragCoord.xy), 0).r;
  if (z >= 1.0)
  {
    return 1.0e30;
  }
  float n = clipRange.x;
  float f = clipRange.y;
  return parallelView == 1 ? n + z * (f - n) : n * f / (f - z * (f - n));
}

float tableIndex(float s, vec2 range)
{
  float x = (clamp(s, range.x, range.y) - tableAxis.x) * tableAxis.y;
  return (clamp(x, 0.0, tableAxis.z - 1.0) + 0.5) / tableAxis.z;
}

vec4 lookup3d(float u, float v, float len)
{
  float k = clamp(len * tableLength.x, 0.0, tableLength.y - 1.0);
  return texture(ptTable, vec3((k + 0.5) / tableLength.y, v, u));
}

vec4 lookupSeparable(float u, float v, float len)
{
  int layers = int(tableLength.z) + 1;
  float nz = float(layers);
  vec4 head = texture(ptTable, vec3(u, v, 0.5 / nz));
  float alpha = 1.0 - exp(-len * head.x);
  float w = clamp(len * tableLength.x, 0.0, 1.0);
  vec3 chroma = vec3(0.0);
  for (int i = layers - 1; i >= 1; --i)
  {
    chroma = chroma * w + texture(ptTable, vec3(u, v, (float(i) + 0.5) / nz)).rgb;
  }
  chroma = chroma * w + head.yzw;
  return vec4(clamp(chroma, vec3(0.0), kappaMax) * alpha, alpha);
}

void main()
{
  float px = gl_FragCoord.x - 0.5;
  float py = viewHeight - gl_FragCoord.y - 0.5;
  vec3 o = rayO0 + px * rayOx + py * rayOy;
  vec3 d = rayD0 + px * rayDx + py * rayDy;
  float t0 = clipRange.x;
  float t1 = clipRange.y;
  if (useDepth == 1)
  {
    t1 = min(t1, opaqueLimit());
  }
  clipPlane(cellPlane0, o, d, t0, t1);
  clipPlane(cellPlane1, o, d, t0, t1);
  clipPlane(cellPlane2, o, d, t0, t1);
  clipPlane(cellPlane3, o, d, t0, t1);
  for (int i = 0; i < clipCount; ++i)
  {
    clipPlane(clipPlanes[i], o, d, t0, t1);
  }
  if (!(t1 > t0))
  {
    discard;
  }
  float len = (t1 - t0) * length(d);
  float sf = dot(cellScalar.xyz, o + t0 * d) + cellScalar.w;
  float sb = dot(cellScalar.xyz, o + t1 * d) + cellScalar.w;
  float u = tableIndex(sf, cellRange.xy);
  float v = tableIndex(sb, cellRange.xy);
  vec4 rgba = lookupKind == 1 ? lookupSeparable(u, v, len) : lookup3d(u, v, len);
  gl_FragData[0] = rgba;
  gl_FragDepth = 0.0;
}
