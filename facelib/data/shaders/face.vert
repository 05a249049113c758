#version 330 core
// facelib's face vertex shader: passes world-space position, normal and the per-vertex
// colour (sRGB converted to linear, ambient occlusion already multiplied in) to face.frag,
// and the occlusion factor itself (the colour's alpha), which dims the highlights.
// Attribute locations and the M/V/P uniforms are the ones pyrender binds for any mesh.
// Hair cards (the only primitives with texture coordinates) pass their card coordinates on.

layout(location = 0) in vec3 position;
layout(location = NORMAL_LOC) in vec3 normal;
#ifdef COLOR_0_LOC
layout(location = COLOR_0_LOC) in vec4 color_0;
#endif
#ifdef TEXCOORD_0_LOC
layout(location = TEXCOORD_0_LOC) in vec2 texcoord_0;  // hair cards: (card + across, root to tip)
out vec2 hair_uv;
#endif
#ifdef TEXCOORD_1_LOC
// skin: its shine and roughness factors (facelib/rendering/skin_map.py)
layout(location = TEXCOORD_1_LOC) in vec2 texcoord_1;
out vec2 surface;
#endif
#ifdef TANGENT_LOC
// skin that wrinkles: (phase, depth) of wrinkle channels 0 and 1
layout(location = TANGENT_LOC) in vec4 tangent;
out vec4 wrinkle;
#endif
// pyrender's per-instance model matrix (inst_m, at INST_M_LOC) is left out: facelib never
// instances a primitive, so it is the identity, and M * identity is M exactly; dropping it
// spares llvmpipe's vertex stage (on the main thread) a matrix product and four attribute
// fetches a vertex

uniform mat4 M;
uniform mat4 V;
uniform mat4 P;

out vec3 world_position;
out vec3 world_normal;
out vec3 albedo;
out float occlusion;

void main()
{
    vec4 world = M * vec4(position, 1.0);
    gl_Position = P * V * world;
    world_position = world.xyz;
    // facelib's node poses are rigid (rotations and translations), so the model matrix's
    // upper 3x3 turns normals as it turns positions (face.frag normalises): no inverse per
    // vertex, which llvmpipe pays on the thread that also bins the triangles
    world_normal = mat3(M) * normal;
#ifdef TEXCOORD_0_LOC
    hair_uv = texcoord_0;
#endif
#ifdef TEXCOORD_1_LOC
    surface = texcoord_1;
#endif
#ifdef TANGENT_LOC
    wrinkle = tangent;
#endif
#ifdef COLOR_0_LOC
    albedo = color_0.rgb;
    occlusion = color_0.a;
#else
    albedo = vec3(0.8);
    occlusion = 1.0;
#endif
}
