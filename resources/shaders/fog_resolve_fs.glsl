//VTK::System::Dec

// The fog layer's resolve (Roettger section 10.3, the modes of volviz.nature.fog): the per-pixel sum (or maximum) the
// prisms left in the layer's float target becomes premultiplied RGBA, composited over the scene with
// (ONE, ONE_MINUS_SRC_ALPHA):
//   emissive    RGB = color * density * sum, alpha 0 (additive);
//   attenuated  tau = density * sum, alpha = 1 - exp(-tau), RGB = color * alpha;
//   mip         alpha = min(gain * max, 1), RGB = color * alpha.

uniform sampler2D fogAccum;
uniform int fogMode;          // 0 emissive, 1 attenuated, 2 mip
uniform vec3 fogColor;
uniform float fogDensity;
uniform float fogGain;

//VTK::Output::Dec

void main()
{
  float v = texelFetch(fogAccum, ivec2(gl_FragCoord.xy), 0).r;
  if (!(v > 0.0))
  {
    discard;
  }
  vec4 rgba;
  if (fogMode == 0)
  {
    rgba = vec4(fogColor * (fogDensity * v), 0.0);
  }
  else
  {
    float a = fogMode == 1 ? 1.0 - exp(-fogDensity * v) : min(fogGain * v, 1.0);
    rgba = vec4(fogColor * a, a);
  }
  gl_FragData[0] = rgba;
  gl_FragDepth = 0.0;
}
