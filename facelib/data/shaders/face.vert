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
// skin with a wrinkle layout (facelib/rendering/skin_map.py): channel 0 (phase, depth) in
// texcoord_1, channel 1 (phase, depth) and the skin's shine factor in the tangent
layout(location = TEXCOORD_1_LOC) in vec2 texcoord_1;
layout(location = TANGENT_LOC) in vec4 tangent;
out vec4 wrinkle;
out float shine;
#endif
layout(location = INST_M_LOC) in mat4 inst_m;

uniform mat4 M;
uniform mat4 V;
uniform mat4 P;

out vec3 world_position;
out vec3 world_normal;
out vec3 albedo;
out float occlusion;

void main()
{
    mat4 model = M * inst_m;
    vec4 world = model * vec4(position, 1.0);
    gl_Position = P * V * world;
    world_position = world.xyz;
    world_normal = mat3(transpose(inverse(model))) * normal;
#ifdef TEXCOORD_0_LOC
    hair_uv = texcoord_0;
#endif
#ifdef TEXCOORD_1_LOC
    wrinkle = vec4(texcoord_1, tangent.xy);
    shine = tangent.z;
#endif
#ifdef COLOR_0_LOC
    albedo = color_0.rgb;
    occlusion = color_0.a;
#else
    albedo = vec3(0.8);
    occlusion = 1.0;
#endif
}
