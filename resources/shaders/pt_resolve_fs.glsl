//VTK::System::Dec

// The GPU PT volume's resolve: the premultiplied RGBA the cells left in the volume's own float32 target (composited
// back to front from transparent black) goes "over" the scene with (ONE, ONE_MINUS_SRC_ALPHA), per sample of a
// multisampled window. Depth 0: the opaque scene does not hide it (the cells were already clipped at its depth).

uniform sampler2D ptAccum;
uniform int ptDrawn;          // 0: no cell was drawn this frame (the target holds an old image)

//VTK::Output::Dec

void main()
{
  vec4 rgba = texelFetch(ptAccum, ivec2(gl_FragCoord.xy), 0);
  if (ptDrawn == 0 || !(rgba.a > 0.0 || rgba.r > 0.0 || rgba.g > 0.0 || rgba.b > 0.0))
  {
    discard;
  }
  gl_FragData[0] = rgba;
  gl_FragDepth = 0.0;
}
