// The pixel ray and the opaque scene's depth at the pixel (included by volviz's ray-segment shaders).
//
// The ray O + t D (D . forward = 1, so t is the depth along the direction of projection) is rebuilt from
// gl_FragCoord with the camera's affine ray basis, exactly as the CPU renderers' rays (Camera.rays); positions are
// relative to the drawn object's centre. opaqueLimit() is the depth of the opaque scene at the pixel, read from the
// scene's depth texture (1e30 where nothing opaque was drawn).

uniform vec3 rayO0;
uniform vec3 rayOx;
uniform vec3 rayOy;
uniform vec3 rayD0;
uniform vec3 rayDx;
uniform vec3 rayDy;
uniform float viewHeight;
uniform vec2 clipRange;
uniform int parallelView;
uniform sampler2D opaqueDepth;

void pixelRay(out vec3 o, out vec3 d)
{
  float px = gl_FragCoord.x - 0.5;
  float py = viewHeight - gl_FragCoord.y - 0.5;
  o = rayO0 + px * rayOx + py * rayOy;
  d = rayD0 + px * rayDx + py * rayDy;
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
