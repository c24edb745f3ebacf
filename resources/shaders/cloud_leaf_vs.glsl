//VTK::System::Dec

// C-LOD cloud leaves on the projected-tetrahedra pass (Roettger sections 11.3-11.6): one point per leaf slot, drawn
// in the leaves' back-to-front order (the index buffer holds the slots, volviz.render.cloud_slots). The slot's texel
// is the leaf's octree address; this shader morphs the leaf's 8 corners on the GPU, from the eye, and
// cloud_leaf_gs.glsl makes its 5 tetrahedra from them.
//
// The morph is CloudLOD's (volviz.nature._cloud_kernels.decide and morph) in closed form. A node's weight e' (Eq.
// 11.1, 11.6, capped by its parent's) is the minimum over its ancestors and itself of clamp(e - 1, 0, 1), or 0 when
// one of them is not refined (e <= 1, i.e. the eye no nearer than the node's threshold num = s C max(c delta, 1),
// which is 0 for transparent nodes). Top-down along the leaf's ancestors, each child's corners are lattice points of
// its parent: a parent's corner keeps its value, the others get the corrected Eq. (11.8)
// S' = (1 - w) coarse + w S, coarse from the parent's (morphed) corners over its 5-tetrahedra split, w the minimum
// e' of the same-level nodes sharing the point (outside the volume: none).
in vec4 vertexMC;

uniform sampler2D cloudSlots;      // per slot: a, b, c, level (level < 0: no leaf)
uniform int cloudSlotsWidth;
uniform sampler2D cloudFields;     // per grid point (x slowest, z fastest): table field, modulating field / max
uniform int cloudFieldsWidth;
uniform sampler2D cloudNodes;      // per stored node (level-major): its refinement threshold num
uniform int cloudNodesWidth;
uniform int cloudShape[3];         // grid points per axis
uniform int cloudRoots[3];         // root nodes per axis
uniform int cloudRoot;             // root node edge in grid cells (2^levels)
uniform int cloudOffsets[16];      // first stored node of each level
uniform int cloudGeomorph;
uniform vec3 cloudOrigin;          // the grid's origin in model coordinates (relative to the actor's position)
uniform vec3 cloudSpacing;
uniform vec3 cloudEye;             // the camera's position in model coordinates

flat out ivec4 leafPlace;          // lowest grid point, edge in grid cells (0: nothing to draw)
flat out vec4 leafTableLow;        // the table field at corners q = 4 i + 2 j + k, 0-3 and 4-7
flat out vec4 leafTableHigh;
flat out vec4 leafModulateLow;     // the modulating field over its maximum, likewise
flat out vec4 leafModulateHigh;

vec4 texel(sampler2D table, int width, int index)
{
  return texelFetch(table, ivec2(index % width, index / width), 0);
}

ivec3 bits(int q)
{
  return ivec3((q >> 2) & 1, (q >> 1) & 1, q & 1);
}

vec2 field(ivec3 p)
{
  return texel(cloudFields, cloudFieldsWidth, (p.x * cloudShape[1] + p.y) * cloudShape[2] + p.z).xy;
}

bool inside(int level, ivec3 n)
{
  ivec3 dims = ivec3(cloudRoots[0], cloudRoots[1], cloudRoots[2]) << level;
  return all(greaterThanEqual(n, ivec3(0))) && all(lessThan(n, dims));
}

// clamp(e - 1, 0, 1) of one node (1 without geomorphing) if Eq. (11.1) refines it, else 0
float ownWeight(int level, ivec3 n)
{
  ivec3 dims = ivec3(cloudRoots[0], cloudRoots[1], cloudRoots[2]) << level;
  float num = texel(cloudNodes, cloudNodesWidth, cloudOffsets[level] + (n.x * dims.y + n.y) * dims.z + n.z).x;
  vec3 centre = cloudOrigin + (vec3(n) + 0.5) * cloudSpacing * float(cloudRoot >> level);
  float d = distance(centre, cloudEye);
  if (!(d < num))
  {
    return 0.0;
  }
  return (cloudGeomorph == 0 || d <= 0.0) ? 1.0 : clamp(num / d - 1.0, 0.0, 1.0);
}

// the leaf's ancestors (level, address) and their e'; a neighbour's e' walks up its own ancestors until they meet
ivec3 chainNode[16];
float chainWeight[16];

float weight(int level, ivec3 n)
{
  float w = 1.0;
  for (int l = level; l >= 0; --l)
  {
    ivec3 m = n >> (level - l);
    if (m == chainNode[l])
    {
      return min(w, chainWeight[l]);
    }
    w = min(w, ownWeight(l, m));
    if (w <= 0.0)
    {
      return 0.0;
    }
  }
  return w;
}

// the parent's 5-tetrahedra interpolation at lattice point p in {0, 1, 2}^3 (parity: its central tetrahedron's
// corners): an edge midpoint the mean of the edge's ends, a face centre of the face's parity diagonal, the centre
// of the central tetrahedron (_cloud_kernels.coarse_value)
vec2 coarse(vec2 corner[8], ivec3 p, int parity)
{
  ivec3 odd = p & 1;
  int nOdd = odd.x + odd.y + odd.z;
  if (nOdd == 1)
  {
    ivec3 lo = p >> 1;
    ivec3 hi = lo + odd;
    return 0.5 * (corner[(lo.x << 2) | (lo.y << 1) | lo.z] + corner[(hi.x << 2) | (hi.y << 1) | hi.z]);
  }
  vec2 sum = vec2(0.0);
  float count = 0.0;
  for (int c = 0; c < 8; ++c)
  {
    ivec3 b = bits(c);
    if (((b.x + b.y + b.z) & 1) != parity)
    {
      continue;
    }
    ivec3 side = p >> 1;
    if (nOdd == 2 && ((odd.x == 0 && b.x != side.x) || (odd.y == 0 && b.y != side.y) || (odd.z == 0 && b.z != side.z)))
    {
      continue;                       // a face centre: only the face's corners
    }
    sum += corner[c];
    count += 1.0;
  }
  return sum / count;
}

void main()
{
  vec4 slot = texel(cloudSlots, cloudSlotsWidth, gl_VertexID);
  int level = int(slot.w);
  gl_Position = vertexMC;
  if (level < 0)
  {
    leafPlace = ivec4(0);
    return;
  }
  ivec3 leaf = ivec3(slot.xyz);
  ivec3 node = leaf >> level;
  int size = cloudRoot;
  vec2 corner[8];
  for (int q = 0; q < 8; ++q)
  {
    corner[q] = field((node + bits(q)) * size);
  }
  float chain = 1.0;
  for (int l = 0; l < level; ++l)
  {
    node = leaf >> (level - l);
    chain = min(chain, ownWeight(l, node));
    chainNode[l] = node;
    chainWeight[l] = chain;
    ivec3 octant = (leaf >> (level - l - 1)) & 1;
    ivec3 toward = 2 * octant - 1;
    // e' of this node's 7 neighbours toward the child's octant (mask m: the axes it is displaced along)
    float beside[8];
    beside[0] = chain;
    for (int m = 1; m < 8; ++m)
    {
      ivec3 n = node + bits(m) * toward;
      beside[m] = inside(l, n) ? weight(l, n) : chain;
    }
    int parity = (node.x + node.y + node.z) & 1;
    int halfSize = size >> 1;
    vec2 child[8];
    for (int c = 0; c < 8; ++c)
    {
      ivec3 p = octant + bits(c);              // the child's corner in the parent's lattice
      ivec3 odd = p & 1;
      if (odd == ivec3(0))
      {
        child[c] = corner[((p.x >> 1) << 2) | ((p.y >> 1) << 1) | (p.z >> 1)];
        continue;
      }
      int boundary = ((1 - odd.x) << 2) | ((1 - odd.y) << 1) | (1 - odd.z);
      float w = chain;
      for (int m = 1; m < 8; ++m)
      {
        if ((m & boundary) == m)
        {
          w = min(w, beside[m]);
        }
      }
      child[c] = (1.0 - w) * coarse(corner, p, parity) + w * field(node * size + p * halfSize);
    }
    for (int c = 0; c < 8; ++c)
    {
      corner[c] = child[c];
    }
    size = halfSize;
  }
  leafPlace = ivec4(leaf * size, size);
  leafTableLow = vec4(corner[0].x, corner[1].x, corner[2].x, corner[3].x);
  leafTableHigh = vec4(corner[4].x, corner[5].x, corner[6].x, corner[7].x);
  leafModulateLow = vec4(corner[0].y, corner[1].y, corner[2].y, corner[3].y);
  leafModulateHigh = vec4(corner[4].y, corner[5].y, corner[6].y, corner[7].y);
}
