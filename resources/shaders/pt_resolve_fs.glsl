//VTK::System::Dec

// The GPU PT volume's resolve: the premultiplied RGBA the cells left in the volume's own float32 target (composited
// back to front from transparent black) goes "over" the scene with (ONE, ONE_MINUS_SRC_ALPHA), per sample of a
// multisampled window. Depth 0: the opaque scene does not hide it (the cells were already clipped at its depth).
// With PT_UPSAMPLE defined (an interactive frame drawn at reduced resolution, volviz.render.reduced_fill) the target
// is smaller than the viewport and is sampled bilinearly at each pixel's centre (premultiplied colors interpolate
// correctly); without it, one texel per pixel (texelFetch: the full-resolution frame exactly as drawn).

uniform sampler2D ptAccum;
uniform int ptDrawn;          // 0: no cell was drawn this frame (the target holds an old image)
#ifdef PT_UPSAMPLE
uniform vec2 ptViewSize;      // the viewport's width and height in pixels
#endif

//VTK::Output::Dec

void main()
{
#ifdef PT_UPSAMPLE
  vec4 rgba = texture(ptAccum, gl_FragCoord.xy / ptViewSize);
#else
  vec4 rgba = texelFetch(ptAccum, ivec2(gl_FragCoord.xy), 0);
#endif
  if (ptDrawn == 0 || !(rgba.a > 0.0 || rgba.r > 0.0 || rgba.g > 0.0 || rgba.b > 0.0))
  {
    discard;
  }
  gl_FragData[0] = rgba;
  gl_FragDepth = 0.0;
}
