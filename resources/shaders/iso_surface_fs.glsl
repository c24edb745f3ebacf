//VTK::System::Dec

// Semi-transparent isosurfaces (libMini note section 4, volviz.render.gl_iso): one fragment program for every pass;
// isoPass selects what the fragment writes. Shading as volviz.iso.composite: opacity alpha = the surface opacity, or
// the iso-spectrum 1 - clamp(mu^a - b, 0, 1) ("Shaded Iso-Surfaces"); head-light color c (k_a + (1 - k_a) mu).
//   0 opaque surface          (c_lit, 1)
//   1 "over" (2-pass, exact)  (c_lit, alpha), straight: VTK's (SRC_ALPHA, ONE_MINUS_SRC_ALPHA) blending, or depth
//                             peeling through the //VTK::DepthPeeling tags
//   2 attenuation             (0, alpha): C <- (1 - alpha) C
//   3 back faces              depth only, into volviz's own framebuffer (front faces discarded)
//   4 emission                (alpha c_lit, 0) with (ONE, ONE_MINUS_SRC_ALPHA): C <- C + e; with isoClipZ only
//                             fragments at or in front of the front-most back face (4-pass)

in float isoMu;
flat in vec4 styleVSOut;
flat in vec2 fitVSOut;

uniform int isoPass;
uniform int isoClipZ;
uniform float isoAmbient;
uniform sampler2D isoBackDepth;

//VTK::DepthPeeling::Dec

//VTK::Output::Dec

void main()
{
  //VTK::Depth::Impl

  //VTK::DepthPeeling::PreColor

  float mu = clamp(isoMu, 0.0, 1.0);
  float alpha = styleVSOut.a;
  if (fitVSOut.x > 0.0)
  {
    alpha = 1.0 - clamp(pow(mu, fitVSOut.x) - fitVSOut.y, 0.0, 1.0);
  }
  vec3 lit = styleVSOut.rgb * (isoAmbient + (1.0 - isoAmbient) * mu);
  if (isoPass == 0)
  {
    gl_FragData[0] = vec4(lit, 1.0);
  }
  else if (isoPass == 1)
  {
    gl_FragData[0] = vec4(lit, alpha);
  }
  else if (isoPass == 2)
  {
    gl_FragData[0] = vec4(0.0, 0.0, 0.0, alpha);
  }
  else if (isoPass == 3)
  {
    if (gl_FrontFacing)
    {
      discard;
    }
    gl_FragData[0] = vec4(0.0);
  }
  else
  {
    if (isoClipZ != 0 && gl_FragCoord.z > texelFetch(isoBackDepth, ivec2(gl_FragCoord.xy), 0).r)
    {
      discard;
    }
    gl_FragData[0] = vec4(alpha * lit, 0.0);
  }

  //VTK::DepthPeeling::Impl
}
