// The raster visibility backend (src/visibility/raster/raster_tracer.cpp):
// depth maps drawn into the layers of a depth texture array, then turned into
// "blocked" bits by a compute pass. The C++ side prepends #version 430 core
// and defines one stage (SKYBAKE_STAGE_VS, _GS, _FS, _CS), one method
// (SKYBAKE_CUBE or SKYBAKE_DIRECTIONAL), for BackFaces::Ignore
// SKYBAKE_IGNORE_BACK_FACES, and SKYBAKE_VS_LAYER where the vertex shader can
// choose the layer (then there is no geometry shader).
//
// One layer is one view:
//   cube         layer 5·v + f is face f of vertex v's hemicube, in the
//                vertex's frame (t, b, n): f = 0 looks along n, f = 1 ... 4
//                along +t, −t, +b, −b, each a 90° square (of the side faces
//                only the upper half, n·x ≥ 0, is read). The depth is
//                near / (distance along the face's axis), reversed z
//                (raster_tracer.cpp: cube_projection), with no far plane.
//   directional  layer j is an orthographic view along −x_j of the whole mesh,
//                from outside its bounding sphere; the depth is linear.
// Per layer, u_view[layer] takes world space (relative to u_eye[layer].xyz
// for the cube) to clip space, and u_eye[layer] is (origin, 1) for the cube
// and (x_j, 0) for the directional maps.

layout(std430, binding = 0) readonly buffer Views { mat4 u_view[]; };
layout(std430, binding = 1) readonly buffer Eyes { vec4 u_eye[]; };

#if defined(SKYBAKE_STAGE_VS)
#if defined(SKYBAKE_VS_LAYER)
// The layer is chosen here (GL_ARB_shader_viewport_layer_array, enabled by the
// C++ side) and there is no geometry stage: the clipper drops what is outside
// a view and face culling drops back faces (SKYBAKE_IGNORE_BACK_FACES).
#define v_rel g_rel
#endif
layout(location = 0) in vec3 a_position;
#if defined(SKYBAKE_CUBE)
// One indirect draw per layer, of the triangles binned to it: its
// baseInstance selects the layer id (divisor 1).
layout(location = 1) in int a_layer;
#define SB_LAYER a_layer
#else
#define SB_LAYER gl_InstanceID
#endif
out vec3 v_rel;
flat out int v_layer;
void main() {
    v_layer = SB_LAYER;
#if defined(SKYBAKE_VS_LAYER)
    gl_Layer = SB_LAYER;
#endif
    const vec4 e = u_eye[SB_LAYER];
#if defined(SKYBAKE_CUBE)
    v_rel = a_position - e.xyz; // relative to the ray origin: no cancellation far from the world origin
    gl_Position = u_view[SB_LAYER] * vec4(v_rel, 1.0);
#else
    v_rel = a_position;
    gl_Position = u_view[SB_LAYER] * vec4(a_position, 1.0);
#endif
}
#endif

#if defined(SKYBAKE_STAGE_GS)
layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;
in vec3 v_rel[];
flat in int v_layer[];
out vec3 g_rel;
void main() {
    const int layer = v_layer[0];
    // A triangle wholly outside one clip plane covers nothing: drop it before
    // the rasteriser sets it up.
    const vec4 p0 = gl_in[0].gl_Position, p1 = gl_in[1].gl_Position, p2 = gl_in[2].gl_Position;
    if ((p0.x > p0.w && p1.x > p1.w && p2.x > p2.w) || (p0.x < -p0.w && p1.x < -p1.w && p2.x < -p2.w) ||
        (p0.y > p0.w && p1.y > p1.w && p2.y > p2.w) || (p0.y < -p0.w && p1.y < -p1.w && p2.y < -p2.w) ||
        (p0.z < -p0.w && p1.z < -p1.w && p2.z < -p2.w))
        return;
#if defined(SKYBAKE_IGNORE_BACK_FACES)
    // Rays pass through a triangle they meet from behind: the ray towards it
    // (from the origin, or along x_j) has a positive dot with its front normal.
    const vec3 front = cross(v_rel[1] - v_rel[0], v_rel[2] - v_rel[0]);
#if defined(SKYBAKE_CUBE)
    const vec3 ray = v_rel[0];
#else
    const vec3 ray = u_eye[layer].xyz;
#endif
    if (dot(front, ray) >= 0.0)
        return;
#endif
    for (int i = 0; i < 3; ++i) {
        gl_Position = gl_in[i].gl_Position;
        gl_Layer = layer;
        g_rel = v_rel[i];
        EmitVertex();
    }
    EndPrimitive();
}
#endif

#if defined(SKYBAKE_STAGE_FS)
// Depth only: the cube's depth comes from its projection (reversed z), the
// directional maps' is linear.
void main() {}
#endif

#if defined(SKYBAKE_STAGE_CS)
// One invocation per (vertex, word): the word's directions, as "blocked" bits
// in visiting order (the C++ side masks the horizon and reorders).
layout(local_size_x = 64) in;
struct Vertex {
    vec4 origin;        // xyz: ray origin
    vec4 t, b, n;       // cube: the vertex's frame; directional: t the origin's offset direction; n: the normal
    vec4 r0, r1, r2;    // rotation columns (rules with +rotate)
};
layout(std430, binding = 2) readonly buffer Points { vec4 u_points[]; };
layout(std430, binding = 3) readonly buffer Vertices { Vertex u_vertices[]; };
layout(std430, binding = 4) buffer Words { uint u_words[]; };
uniform sampler2DArray u_depth;
uniform int u_count;       // vertices in this dispatch
uniform int u_first;       // their first index in the chunk (cube: the batch's first)
uniform int u_words_per_vertex;
uniform int u_first_word;  // the dispatch's words: [u_first_word, u_first_word + u_word_count)
uniform int u_word_count;
uniform int u_first_point; // directional: the batch's directions [u_first_point, u_last_point)
uniform int u_last_point;
uniform int u_rotate;
uniform int u_resolution;
uniform float u_far;       // cube: the near plane (depth = near / axial distance); directional: the depth range
uniform float u_t_max;     // cube: occluders further are ignored
uniform float u_lookup;    // directional: the normal offset, world units (kLookupTexels texels)
uniform float u_recheck;   // directional: a blocker nearer than this beyond the look-up point (world units) is an edge
uniform int u_edge_offset; // directional: where the "edge" words start in u_words (after the chunk's blocked words)

ivec2 texel_of(vec2 ndc) {
    return clamp(ivec2(floor((ndc * 0.5 + 0.5) * float(u_resolution))), ivec2(0), ivec2(u_resolution - 1));
}

#if defined(SKYBAKE_CUBE)
// Whether texel t of a cube face holds a surface within u_t_max of the ray
// origin along the texel centre's ray. Its depth is near / d, d the distance
// along the face's axis; the ray's length is d·|(X, Y, 1)|, with (X, Y) in
// [−1, 1]² the centre's tangents.
bool cube_hit(ivec2 t, int layer) {
    const float depth = texelFetch(u_depth, ivec3(t, layer), 0).r;
    if (!(depth > 0.0))
        return false; // nothing drawn
    if (u_t_max >= 3.0e38)
        return true;
    const vec2 c = (vec2(t) + 0.5) / float(u_resolution) * 2.0 - 1.0;
    return u_far / depth * length(vec3(c, 1.0)) <= u_t_max;
}
#endif

void main() {
    // Dispatches over 65,535 groups are 2D (raster_tracer.cpp: dispatch).
    const int id = int(gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x);
    if (id >= u_count * u_word_count)
        return;
    const int v = id / u_word_count, w = u_first_word + id % u_word_count;
    const Vertex vx = u_vertices[v];
    const int j0 = max(32 * w, u_first_point), j1 = min(32 * w + 32, u_last_point);
    const int slot = (u_first + v) * u_words_per_vertex + w;
    uint bits = 0u;
    uint edge = 0u; // the four texels disagree (a blocker's edge): left to the CPU tracer
    for (int j = j0; j < j1; ++j) {
        vec3 x = u_points[j].xyz;
#if defined(SKYBAKE_CUBE)
        if (u_rotate != 0)
            x = x.x * vx.r0.xyz + x.y * vx.r1.xyz + x.z * vx.r2.xyz;
        const vec3 l = vec3(dot(x, vx.t.xyz), dot(x, vx.b.xyz), dot(x, vx.n.xyz));
        const float ax = abs(l.x), ay = abs(l.y);
        const int face = l.z >= max(ax, ay) ? 0 : ax >= ay ? (l.x > 0.0 ? 1 : 2) : (l.y > 0.0 ? 3 : 4);
        const int layer = 5 * v + face;
        const vec4 clip = u_view[layer] * vec4(x, 0.0);
        const vec2 ndc = clip.xy / clip.w;
        if (cube_hit(texel_of(ndc), layer))
            bits |= 1u << uint(j & 31);
        // The texel's centre stands for the direction: where the four texels
        // around the direction disagree, a blocker's edge passes within a
        // texel of it, and the CPU tracer answers instead (answer_edges); so
        // it does along the face's border.
        const ivec2 i0 = ivec2(floor((ndc * 0.5 + 0.5) * float(u_resolution))) - 1;
        bool any_hit = false, any_open = false;
        for (int dy = 0; dy < 3; ++dy)
            for (int dx = 0; dx < 3; ++dx) {
                const ivec2 t = clamp(i0 + ivec2(dx, dy), ivec2(0), ivec2(u_resolution - 1));
                const bool h = cube_hit(t, layer);
                any_hit = any_hit || h;
                any_open = any_open || !h;
            }
        const bool border = any(lessThan(i0, ivec2(0))) || any(greaterThan(i0 + 2, ivec2(u_resolution - 1)));
        if ((any_hit && any_open) || border)
            edge |= 1u << uint(j & 31);
#else
        const int layer = j - u_first_point;
        // Normal offset (docs/baking.md): the look-up point is 2.1 texels
        // further from the surface than the ray origin, along the driver's
        // offset direction (vx.t: n, or n + u normalised on borders and
        // creases), so at least 1.5 texels along n. The four texel centres
        // around its projection are at most texel·√2 from it, where the plane
        // of normal n through the origin lies (1.5 − 1.42·sin θ)·texel / cos θ
        // > 0 below it along x: the vertex's own surfaces never shadow it,
        // even at grazing directions, and only a small constant bias remains,
        // for depth rounding.
        const vec3 q = vx.origin.xyz + u_lookup * vx.t.xyz;
        const vec4 clip = u_view[layer] * vec4(q, 1.0);
        const float mine = clip.z * 0.5 + 0.5 - 1e-6;
        // Percentage-closer filtering of the four texels around the point,
        // blocked when their bilinear weight is over one half: the edge of a
        // blocker is placed between texel centres instead of on them.
        const vec2 f = (clip.xy * 0.5 + 0.5) * float(u_resolution) - 0.5;
        const ivec2 i0 = ivec2(floor(f));
        const vec2 w = f - vec2(i0);
        float blocked = 0.0;
        float gap = 2.0; // the nearest blocker's distance beyond the look-up point, in depth units
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) {
                const ivec2 t = clamp(i0 + ivec2(dx, dy), ivec2(0), ivec2(u_resolution - 1));
                const float depth = texelFetch(u_depth, ivec3(t, layer), 0).r;
                const float weight = (dx == 1 ? w.x : 1.0 - w.x) * (dy == 1 ? w.y : 1.0 - w.y);
                blocked += depth < mine ? weight : 0.0;
                gap = depth < mine ? min(gap, mine - depth) : gap;
            }
        if (blocked > 0.5)
            bits |= 1u << uint(j & 31);
        if ((blocked > 1e-4 && blocked < 0.9999) || (blocked > 0.5 && gap * u_far < u_recheck))
            edge |= 1u << uint(j & 31);
#endif
    }
#if defined(SKYBAKE_CUBE)
    u_words[slot] = bits;
    u_words[u_edge_offset + slot] = edge;
#else
    u_words[slot] = (u_first_point > 32 * w ? u_words[slot] : 0u) | bits;
    u_words[u_edge_offset + slot] = (u_first_point > 32 * w ? u_words[u_edge_offset + slot] : 0u) | edge;
#endif
}
#endif
