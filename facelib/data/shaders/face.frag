#version 330 core
// facelib's face fragment shader: a cheap replacement for pyrender's PBR shader (which
// costs about two thirds of a 640x480 frame on llvmpipe), fed by the same uniforms.
//
// Per directional light (the key, fill and rim of render_look.json):
//   diffuse  = albedo / pi * radiance * max((n.l + w) / (1 + w), 0)   "wrap" lighting:
//              the terminator is pushed past 90 degrees by w = WRAP * roughness, which
//              imitates light scattered under matte skin; glossy eyes barely wrap;
//   specular = F0 * (s + 8) / (8 pi) * (n.h)^s * max(n.l, 0) * radiance   normalised
//              Blinn-Phong, with the exponent s = 2 / roughness^4 - 2 that matches a
//              microfacet lobe of that roughness, and F0 = SPECULAR (dielectric, ~0.04);
// plus albedo * ambient. The albedo (vertex colour) carries the baked ambient occlusion,
// and the specular is dimmed by the same factor (light that cannot reach a cavity does not
// glint in it either).
// Output: linear colour to sRGB with gamma 1/2.2, as pyrender's own shader does.
// WRAP and SPECULAR are #defines filled in from render_look.json ("shading").
//
// Hair cards (primitives with texcoord_0 = (card index + across the card, root 0 to tip 1))
// are shaded as strands instead (Kajiya-Kay): the strand tangent t is the direction in which
// the root-to-tip coordinate grows (its world-space gradient over the triangle, from screen
// derivatives, so no tangents need uploading per frame); the highlight follows
// sin(t, h)^s = sqrt(1 - (t.h)^2)^s, a white lobe with the tangent shifted toward the root
// (HAIR_SHIFT) and a wider, hair-coloured second lobe shifted toward the tip, as light
// reflected inside the fibre comes out. The card is cut into HAIR_STRANDS strands across,
// each a little lighter or darker and ending a little earlier (HAIR_TIPS), so a card reads
// as a lock of hair, not a ribbon. Both faces of a card are lit (normal toward the viewer).
//
// Skin (primitives with texcoord_1 = its shine and roughness factors; the ones a wrinkle
// region reaches also carry tangent = two wrinkle channels; facelib/rendering/skin_map.py)
// gets three more things:
//   wrinkles: two channels of (phase s, depth a); the skin is creased where s is a whole
//     number: the valley profile v (about ((1 + cos 2 pi s) / 2)^2, see crease) darkens
//     the colour by 1 - WRINKLE_CREASE * a * v and tilts the normal across the line by the
//     slope of the height -a * v (times WRINKLE_BUMP), along the world-space gradient of s (from
//     screen derivatives, as the hair's tangent); lines finer than about three pixels fade
//     out instead of aliasing;
//   scattering: the wrap is wider in red and narrower in blue (SKIN_SCATTER), so the
//     terminator warms as light scattered under the skin comes out red;
//   shine and roughness: the specular and the roughness times per-vertex factors
//     (texcoord_1; the look's skin_tint: an oilier forehead and nose, glossier lips, the
//     wet line of the lower lids).

struct DirectionalLight {
    vec3 color;
    float intensity;
    vec3 direction;
};

struct Material {
    vec3 emissive_factor;
    vec4 base_color_factor;
    float metallic_factor;
    float roughness_factor;
};

uniform Material material;
uniform DirectionalLight directional_lights[MAX_DIRECTIONAL_LIGHTS];
// LOOK_LIGHTS: the number of the look's lights, compiled in (facelib/rendering/scene.py's
// install_program_cache) rather than pyrender's n_directional_lights uniform: a loop with
// a constant count is unrolled and its lights read from fixed places, which saves llvmpipe
// about a tenth of this shader's time; the pixels are the same
uniform vec3 cam_pos;
uniform vec3 ambient_light;

in vec3 world_position;
in vec3 world_normal;
in vec3 albedo;
in float occlusion;

out vec4 frag_color;

const float PI = 3.141592653589793;

#ifdef TEXCOORD_1_LOC
in vec2 surface;
#endif
#ifdef TANGENT_LOC
in vec4 wrinkle;

// the crease of one wrinkle channel (phase s, depth a, the screen derivatives ds of s, the
// world-space gradient g of s, the normal n): adds the normal's tilt to tilt and returns the
// darkening factor. The valley is v = b^2 with b = 1 - 3x^2 + 2x^3 (a cubic as round as
// (1 + cos 2 pi s) / 2, without its cost on a software rasteriser), x = 2 |s - round(s)|.
float crease(float s, float a, vec2 ds, vec3 g, vec3 n, inout vec3 tilt)
{
    a *= clamp(1.6 - 3.0 * (abs(ds.x) + abs(ds.y)), 0.0, 1.0);
    float d = s - floor(s + 0.5);
    float x = 2.0 * abs(d);
    float b = 1.0 - x * x * (3.0 - 2.0 * x);
    // dv/ds = 2 b db/dx dx/ds = 2 b (-6 x (1 - x)) (2 sign d)
    float slope = -24.0 * b * x * (1.0 - x) * sign(d);
    vec3 gt = g - n * dot(n, g);
    tilt += (float(WRINKLE_BUMP) * a * slope * inversesqrt(max(dot(gt, gt), 1e-30))) * gt;
    return 1.0 - float(WRINKLE_CREASE) * a * b * b;
}
#endif

#ifdef TEXCOORD_0_LOC
in vec2 hair_uv;

float strand_hash(float n)
{
    return fract(sin(n * 12.9898) * 43758.5453);
}

// Kajiya-Kay highlight of a strand with unit tangent t for the half vector h
float strand_lobe(vec3 t, vec3 h, float exponent)
{
    float th = dot(t, h);
    return pow(sqrt(max(1.0 - th * th, 0.0)), exponent);
}
#endif

void main()
{
    vec3 n = normalize(world_normal);
    vec3 v = normalize(cam_pos - world_position);
#ifdef TEXCOORD_1_LOC
    float roughness = clamp(material.roughness_factor * surface.y, 0.04, 1.0);
    float shine = surface.x;
#else
    float roughness = clamp(material.roughness_factor, 0.04, 1.0);
#endif
    float r2 = roughness * roughness;
    float shininess = max(2.0 / (r2 * r2) - 2.0, 1.0);
    float lobe = float(SPECULAR) * (shininess + 8.0) / (8.0 * PI);
    float wrap = float(WRAP) * roughness;
    vec3 base = albedo * material.base_color_factor.rgb;

    vec3 diffuse = vec3(0.0);
    vec3 specular = vec3(0.0);
#ifdef TEXCOORD_0_LOC
    vec3 dp1 = dFdx(world_position);
    vec3 dp2 = dFdy(world_position);
    float dv1 = dFdx(hair_uv.y);
    float dv2 = dFdy(hair_uv.y);
    vec3 across = cross(dp1, dp2);
    vec3 grad = dv1 * cross(dp2, across) + dv2 * cross(across, dp1);
    vec3 t = grad / max(length(grad), 1e-20);
    float strand = floor(fract(hair_uv.x) * float(HAIR_STRANDS)) + 17.0 * floor(hair_uv.x);
    float luck = strand_hash(strand);
    if (hair_uv.y > 1.0 - float(HAIR_TIPS) * luck) {
        discard;
    }
    if (dot(n, v) < 0.0) {
        n = -n;
    }
    base *= 0.72 + 0.56 * luck;
    vec3 t1 = normalize(t + float(HAIR_SHIFT) * n);
    vec3 t2 = normalize(t - float(HAIR_SHIFT) * n);
    for (int i = 0; i < LOOK_LIGHTS; i++) {
        vec3 l = -directional_lights[i].direction;  // unit: a rigid pose's -z axis
        vec3 radiance = directional_lights[i].color * directional_lights[i].intensity;
        float nl = dot(n, l);
        diffuse += radiance * max((nl + wrap) / (1.0 + wrap), 0.0);
        vec3 h = normalize(l + v);
        float lit = smoothstep(-0.1, 0.4, nl);
        specular += radiance * lit * (float(HAIR_SHINE) * strand_lobe(t1, h, float(HAIR_GLOSS))
                                      + float(HAIR_SHEEN) * strand_lobe(t2, h, 0.25 * float(HAIR_GLOSS)) * 4.0 * base);
    }
#else
#ifdef TEXCOORD_1_LOC
#ifdef TANGENT_LOC
    vec3 dp1 = dFdx(world_position);
    vec3 dp2 = dFdy(world_position);
    vec2 ds0 = vec2(dFdx(wrinkle.x), dFdy(wrinkle.x));
    vec2 ds1 = vec2(dFdx(wrinkle.z), dFdy(wrinkle.z));
    vec3 across = cross(dp1, dp2);
    vec3 ex = cross(dp2, across);
    vec3 ey = cross(across, dp1);
    vec3 tilt = vec3(0.0);
    float folded = crease(wrinkle.x, wrinkle.y, ds0, ds0.x * ex + ds0.y * ey, n, tilt)
                   * crease(wrinkle.z, wrinkle.w, ds1, ds1.x * ex + ds1.y * ey, n, tilt);
    n = normalize(n + tilt);
    base *= folded;
#endif
    vec3 wraps = wrap * (vec3(1.0) + float(SKIN_SCATTER) * vec3(0.8, -0.15, -0.4));
    for (int i = 0; i < LOOK_LIGHTS; i++) {
        vec3 l = -directional_lights[i].direction;  // unit: a rigid pose's -z axis
        vec3 radiance = directional_lights[i].color * directional_lights[i].intensity;
        float nl = dot(n, l);
        diffuse += radiance * max((vec3(nl) + wraps) / (vec3(1.0) + wraps), 0.0);
        float nh = max(dot(n, normalize(l + v)), 0.0);
        specular += radiance * (lobe * shine * pow(nh, shininess) * max(nl, 0.0));
    }
#ifdef TANGENT_LOC
    specular *= folded;
#endif
#else
    for (int i = 0; i < LOOK_LIGHTS; i++) {
        vec3 l = -directional_lights[i].direction;  // unit: a rigid pose's -z axis
        vec3 radiance = directional_lights[i].color * directional_lights[i].intensity;
        float nl = dot(n, l);
        diffuse += radiance * max((nl + wrap) / (1.0 + wrap), 0.0);
        float nh = max(dot(n, normalize(l + v)), 0.0);
        specular += radiance * (lobe * pow(nh, shininess) * max(nl, 0.0));
    }
#endif
#endif
    vec3 color = base * (diffuse / PI + ambient_light) + occlusion * specular;
    frag_color = vec4(pow(clamp(color, 0.0, 1.0), vec3(1.0 / 2.2)), 1.0);
}
