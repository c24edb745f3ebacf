//VTK::System::Dec

// One fragment of a fog prism's back (exit) face (Roettger section 10.3, PCP; the near-plane cap of section 10.4).
//
// The pixel ray O + t D (ray_pixel.glsl: rebuilt from gl_FragCoord, t the depth along the view) is clipped against
// the prism's five half-spaces (three vertical sides n . (x, y) + d >= 0, above the bottom plane z >= zb(x, y), below
// the top plane z <= zt(x, y)), the near plane, the far plane and the opaque scene's depth at this pixel. A prism cut
// by the near plane starts at t = near: that is the cap of section 10.4. The emission field is
// E_b(x, y) + u (E_t(x, y) - E_b(x, y)) with u the height fraction between bottom and top (the CPU's sum over
// barycentric weights, written as affine forms).
//
// Output (into the layer's own float target, not the scene): the emission 1/2 (e_f + e_b) l of the segment, summed by
// additive blending (emissive and attenuated modes), or max(e_f, e_b), kept by blend equation MAX (MIP mode).

flat in vec3 side0;
flat in vec3 side1;
flat in vec3 side2;
flat in vec3 zBottom;
flat in vec3 zTop;
flat in vec3 eBottom;
flat in vec3 eTop;

//VOLVIZ::include ray_pixel.glsl
uniform int mipMode;

//VTK::Output::Dec

// the half-space a + t b >= 0 along the ray
void clipHalf(float a, float b, inout float t0, inout float t1)
{
  if (b > 0.0)
  {
    t0 = max(t0, -a / b);
  }
  else if (b < 0.0)
  {
    t1 = min(t1, -a / b);
  }
  else if (a < 0.0)
  {
    t1 = -1.0e30;
  }
}

float emission(vec3 p)
{
  vec3 h = vec3(p.xy, 1.0);
  float zb = dot(zBottom, h);
  float dz = dot(zTop, h) - zb;
  float u = dz <= 1.0e-12 ? 0.5 : clamp((p.z - zb) / dz, 0.0, 1.0);
  float eb = dot(eBottom, h);
  return eb + u * (dot(eTop, h) - eb);
}

void main()
{
  vec3 o;
  vec3 d;
  pixelRay(o, d);
  float t0 = clipRange.x;
  float t1 = min(clipRange.y, opaqueLimit());
  clipHalf(dot(side0.xy, o.xy) + side0.z, dot(side0.xy, d.xy), t0, t1);
  clipHalf(dot(side1.xy, o.xy) + side1.z, dot(side1.xy, d.xy), t0, t1);
  clipHalf(dot(side2.xy, o.xy) + side2.z, dot(side2.xy, d.xy), t0, t1);
  // above the bottom: z - zb(x, y) >= 0; below the top: zt(x, y) - z >= 0
  clipHalf(o.z - dot(zBottom, vec3(o.xy, 1.0)), d.z - dot(zBottom.xy, d.xy), t0, t1);
  clipHalf(dot(zTop, vec3(o.xy, 1.0)) - o.z, dot(zTop.xy, d.xy) - d.z, t0, t1);
  if (!(t1 > t0))
  {
    discard;
  }
  float ef = emission(o + t0 * d);
  float eb = emission(o + t1 * d);
  float v = mipMode == 1 ? max(ef, eb) : 0.5 * (ef + eb) * (t1 - t0) * length(d);
  gl_FragData[0] = vec4(v, 0.0, 0.0, 0.0);
}
