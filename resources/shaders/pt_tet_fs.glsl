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
//
// Instead of a table, the segment can be evaluated exactly, as the CPU "pt" does: isosurfaces (Roettger sections
// 8.8-8.10, 8.13: the Heaviside limit of the segment, H(0) = 1/2, several surfaces composited in ray order with their
// side's color; smooth shading, section 8.9, with PT_SMOOTH: a headlight through vertex normals, the intensity
// interpolated linearly in the cell through its barycentric coordinates and taken where the ray crosses the surface)
// or pre-classification (section 8.14: the TF applied at both ends, kappa and rho linear in between, integrated in
// closed form). Their data lie in ptTable as rows read by texelFetch.

flat in vec4 cellPlane0;
flat in vec4 cellPlane1;
flat in vec4 cellPlane2;
flat in vec4 cellPlane3;
flat in vec4 cellScalar;
flat in vec4 cellRange;
#ifdef PT_SMOOTH
flat in vec4 cellNormalX;    // x, y, z of the four vertex normals (vertex f opposite face f)
flat in vec4 cellNormalY;
flat in vec4 cellNormalZ;
flat in vec4 cellBary;       // 1 / (d_f - n_f . p_f): barycentric coordinate f = (d_f - n_f . x) * cellBary[f]
uniform vec3 shadeLight;     // the headlight's direction (unit)
uniform float shadeAmbient;
#endif

//VOLVIZ::include ray_pixel.glsl
uniform int useDepth;

// PT_CLIPS user clipping planes (n, d), n . x <= d kept, relative to the mesh centre; their number is compiled in
// (a loop to a uniform count over a uniform array cost llvmpipe a third of the fragment's arithmetic, also with 0).
#ifndef PT_CLIPS
#define PT_CLIPS 0
#endif
#if PT_CLIPS > 0
uniform vec4 clipPlanes[PT_CLIPS];
#endif

// PT_KIND, defined when the shader is made (one program per kind: llvmpipe executes every branch of a fragment
// shader under a lane mask, so a run-time switch would pay for all kinds): 0 3D table, 1 separable table, 2 exact
// isosurfaces, 3 pre-classified.
#ifndef PT_KIND
#define PT_KIND 0
#endif
uniform int rowCount;        // 2: isosurfaces (rows: value, opacity; front color; back color), 3: TF points
uniform float isoThicken;
#if PT_KIND == 1
uniform sampler2DArray ptTable;   // the separable table's layers: bilinear in (s_f, s_b) within a layer
#else
uniform sampler3D ptTable;
#endif
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
  vec4 head = texture(ptTable, vec3(u, v, 0.0));
  float alpha = 1.0 - exp(-len * head.x);
  float w = clamp(len * tableLength.x, 0.0, 1.0);
  vec3 chroma = vec3(0.0);
  for (int i = layers - 1; i >= 1; --i)
  {
    chroma = chroma * w + texture(ptTable, vec3(u, v, float(i))).rgb;
  }
  chroma = chroma * w + head.yzw;
  return vec4(clamp(chroma, vec3(0.0), kappaMax) * alpha, alpha);
}

// --- exact isosurfaces (kind 2) ---------------------------------------------------------------------------------
float heaviside(float a, float v)
{
  return a > v ? 1.0 : (a == v ? 0.5 : 0.0);
}

vec4 isoSegment(float sf, float sb, float hf, float hb)
{
  float lo = min(sf, sb);
  float hi = max(sf, sb);
  bool ascending = sb >= sf;
  float tr = 1.0;
  vec3 c = vec3(0.0);
  for (int i = 0; i < rowCount; ++i)
  {
    int k = ascending ? i : rowCount - 1 - i;
    vec4 head = texelFetch(ptTable, ivec3(k, 0, 0), 0);      // value, opacity
    float v = head.x;
    float h = 0.0;
    if (isoThicken > 0.0)
    {
      h = (lo - isoThicken <= v && v <= hi + isoThicken) ? 1.0 : 0.0;
    }
    else if (lo < hi)
    {
      h = heaviside(v, lo) * heaviside(hi, v);
    }
    float a = h * head.y;
    if (a > 0.0)
    {
      vec3 color = texelFetch(ptTable, ivec3(k, ascending ? 1 : 2, 0), 0).rgb;
      float w = sb != sf ? clamp((v - sf) / (sb - sf), 0.0, 1.0) : 0.5;
      c += tr * a * color * (hf + w * (hb - hf));
      tr *= 1.0 - a;
    }
  }
  return vec4(c, 1.0 - tr);
}

// --- pre-classification (kind 3) -------------------------------------------------------------------------------
vec4 classify(float s)        // (kappa, rho) of the TF at s; outside its range: 0 (rows: kappa and rho; scalar)
{
  int n = rowCount;
  if (!(texelFetch(ptTable, ivec3(0, 1, 0), 0).x <= s && s <= texelFetch(ptTable, ivec3(n - 1, 1, 0), 0).x))
  {
    return vec4(0.0);
  }
  int lo = 0;
  int hi = n - 1;
  while (hi - lo > 1)
  {
    int mid = (lo + hi) / 2;
    if (texelFetch(ptTable, ivec3(mid, 1, 0), 0).x <= s)
    {
      lo = mid;
    }
    else
    {
      hi = mid;
    }
  }
  float s0 = texelFetch(ptTable, ivec3(lo, 1, 0), 0).x;
  float s1 = texelFetch(ptTable, ivec3(lo + 1, 1, 0), 0).x;
  float w = s1 > s0 ? (s - s0) / (s1 - s0) : 1.0;
  return mix(texelFetch(ptTable, ivec3(lo, 0, 0), 0), texelFetch(ptTable, ivec3(lo + 1, 0, 0), 0), w);
}

float erfcxPos(float x)       // e^(x^2) erfc(x), x >= 0 (Numerical Recipes' erfcc without e^(-x^2): rel. error 1.2e-7)
{
  float t = 1.0 / (1.0 + 0.5 * x);
  return t * exp(-1.26551223 + t * (1.00002368 + t * (0.37409196 + t * (0.09678418 + t * (-0.18628806
         + t * (0.27886807 + t * (-1.13520398 + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277)))))))));
}

float dawsonPos(float x)      // Dawson's integral, x >= 0 (Rybicki's method, h = 0.4, 6 terms: error ~2e-7)
{
  if (x < 0.2)
  {
    float x2 = x * x;
    return x * (1.0 - 2.0 / 3.0 * x2 * (1.0 - 0.4 * x2 * (1.0 - 2.0 / 7.0 * x2)));
  }
  int n0 = 2 * int(0.5 * x / 0.4 + 0.5);
  float xp = x - float(n0) * 0.4;
  float e1 = exp(0.8 * xp);
  float e2 = e1 * e1;
  float d1 = float(n0 + 1);
  float d2 = d1 - 2.0;
  float sum = 0.0;
  for (int i = 0; i < 6; ++i)
  {
    float a = (2.0 * float(i) + 1.0) * 0.4;
    sum += exp(-a * a) * (e1 / d1 + 1.0 / (d2 * e1));
    d1 += 2.0;
    d2 -= 2.0;
    e1 *= e2;
  }
  return 0.5641895835 * exp(-xp * xp) * sum;
}

const float GL_X[4] = float[4](0.0917173212, 0.2627662050, 0.3983332387, 0.4801449282);
const float GL_W[4] = float[4](0.1813418917, 0.1568533229, 0.1111905172, 0.0506142681);

vec2 meanTransmittance(float p, float q)   // (M, e^-T), M = integral_0^1 exp(-p x - q x^2) dx, p >= 0, p + 2q >= 0
{
  float t = p + q;
  float et = exp(-t);
  float m;
  if (t <= 1.0)                            // Gauss-Legendre, 8 nodes on [0, 1]
  {
    m = 0.0;
    for (int i = 0; i < 4; ++i)
    {
      float xa = 0.5 - GL_X[i];
      float xb = 0.5 + GL_X[i];
      m += GL_W[i] * (exp(-(p + q * xa) * xa) + exp(-(p + q * xb) * xb));
    }
  }
  else if (abs(q) <= 1.0e-6 * p)
  {
    m = (1.0 - exp(-p)) / p;
  }
  else if (q > 0.0)
  {
    float rq = sqrt(q);
    float z0 = 0.5 * p / rq;
    m = 0.8862269255 / rq * (erfcxPos(z0) - et * erfcxPos(z0 + rq));
  }
  else
  {
    float rq = sqrt(-q);
    float w0 = 0.5 * max(p + 2.0 * q, 0.0) / rq;
    m = (dawsonPos(w0 + rq) - et * dawsonPos(w0)) / rq;
  }
  return vec2(clamp(m, et, 1.0), et);
}

vec4 preclassified(float sf, float sb, float len)
{
  vec4 f = classify(sf);
  vec4 b = classify(sb);
  float p = f.w * len;
  float q = 0.5 * (b.w - f.w) * len;
  if (!(p + q > 0.0))
  {
    return vec4(0.0);
  }
  vec2 mt = meanTransmittance(p, q);
  return vec4(f.rgb * (1.0 - mt.x) + b.rgb * max(mt.x - mt.y, 0.0), 1.0 - mt.y);
}

#ifdef PT_SMOOTH
float shadeAt(vec3 x)         // the vertex intensities interpolated linearly in the cell at x
{
  vec4 d = vec4(cellPlane0.w - dot(cellPlane0.xyz, x), cellPlane1.w - dot(cellPlane1.xyz, x),
                cellPlane2.w - dot(cellPlane2.xyz, x), cellPlane3.w - dot(cellPlane3.xyz, x));
  vec4 nl = cellNormalX * shadeLight.x + cellNormalY * shadeLight.y + cellNormalZ * shadeLight.z;
  vec4 n2 = cellNormalX * cellNormalX + cellNormalY * cellNormalY + cellNormalZ * cellNormalZ;
  vec4 h = mix(vec4(1.0), shadeAmbient + (1.0 - shadeAmbient) * abs(nl), greaterThan(n2, vec4(0.0)));
  return dot(d * cellBary, h);
}
#endif

void main()
{
  vec3 o;
  vec3 d;
  pixelRay(o, d);
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
#if PT_CLIPS > 0
  for (int i = 0; i < PT_CLIPS; ++i)
  {
    clipPlane(clipPlanes[i], o, d, t0, t1);
  }
#endif
  if (!(t1 > t0))
  {
    discard;
  }
  float len = (t1 - t0) * length(d);
  float sf = dot(cellScalar.xyz, o + t0 * d) + cellScalar.w;
  float sb = dot(cellScalar.xyz, o + t1 * d) + cellScalar.w;
#if PT_KIND >= 2
  float sfc = clamp(sf, cellRange.x, cellRange.y);
  float sbc = clamp(sb, cellRange.x, cellRange.y);
#if PT_KIND == 3
  vec4 rgba = preclassified(sfc, sbc, len);
#elif defined(PT_SMOOTH)
  vec4 rgba = isoSegment(sfc, sbc, shadeAt(o + t0 * d), shadeAt(o + t1 * d));
#else
  vec4 rgba = isoSegment(sfc, sbc, 1.0, 1.0);
#endif
#else
  float u = tableIndex(sf, cellRange.xy);
  float v = tableIndex(sb, cellRange.xy);
#if PT_KIND == 1
  vec4 rgba = lookupSeparable(u, v, len);
#else
  vec4 rgba = lookup3d(u, v, len);
#endif
#endif
  gl_FragData[0] = rgba;
}
