"""GLSL sources and a small program wrapper.

The surface shader is :mod:`matshop.render.integrator` written again, formula
for formula, so the viewport and the reference renderer can be compared pixel
by pixel (``tests/test_viewport_gl.py``):

- BRDF: ``kd/pi + F(ks, i.h) D(h) G(i, o) / (4 |i.n| |o.n|)``, Schlick F,
  Cook-Torrance G, D in GGX / Beckmann / Phong / Ashikhmin-Shirley
  (:mod:`matshop.render.brdf`), and the sampled family from its table and its
  inverse CDF, read as the reference reads them (:mod:`.sampled_lobe`);
- environment specular: the *same* filtered importance sampling as the
  reference (not split-sum): the same Hammersley set of ``N`` points mapped
  through the texel's lobe, each sample reading the environment's box-filtered
  mip level whose texel solid angle matches ``4 (o.h) / (N pdf)``, one level
  coarser (``lod_bias``). The mip chain is the reference's own
  (:mod:`.environment_gpu` uploads ``Environment.levels``), so the estimate is
  the reference's up to float32 and texture-filter rounding;
- environment diffuse: the reference's irradiance map, read bilinearly;
- directional lights through the full BRDF; ``ao`` and ``emissive`` as there;
- optionally in two passes (the lit swatch, :mod:`.swatch`): the light-independent
  terms (environment, emission) written unmapped (``u_linear``) into a float
  target once, then read back per pixel (``u_base``) while only the lights move;
- tone mapping: exposure, Narkowicz ACES (or clip), exact sRGB encoding, in
  the shader (the framebuffer is plain 8-bit, no GL_FRAMEBUFFER_SRGB).

Material textures hold shading inputs (:mod:`.shading_maps`), row 0 at
``t = 0`` = texture ``v = 1``, as the reference's ``bilinear`` reads them.
"""

from __future__ import annotations

import numpy as np
from OpenGL import GL

VERSION = "#version 330 core\n"

MAX_LIGHTS = 4
#: D families by the integer the shader switches on
FAMILY_CODES = {"ggx": 0, "beckmann": 1, "phong": 2, "ashikhmin_shirley": 3, "sampled": 4}

MESH_VERTEX = (
    VERSION
    + """
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_tangent;
layout(location = 3) in vec2 a_uv;
uniform mat4 u_view_proj;
uniform vec2 u_uv_scale;
out vec3 v_position;
out vec3 v_normal;
out vec4 v_tangent;
out vec2 v_uv;
void main() {
    v_position = a_position;
    v_normal = a_normal;
    v_tangent = a_tangent;
    v_uv = a_uv * u_uv_scale;
    gl_Position = u_view_proj * vec4(a_position, 1.0);
}
"""
)

_COMMON = """
const float PI = 3.14159265358979;
const float EPS = 1e-6;

// equirect convention of matshop.render.environment: u from -z towards +x, v from +y
vec2 direction_to_uv(vec3 d) {
    return vec2(0.5 + atan(d.x, -d.z) / (2.0 * PI), acos(clamp(d.y, -1.0, 1.0)) / PI);
}

vec3 aces(vec3 x) {
    x = max(x, 0.0);
    return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

vec3 srgb_encode(vec3 x) {
    x = clamp(x, 0.0, 1.0);
    vec3 curve = 1.055 * pow(x, vec3(1.0 / 2.4)) - 0.055;
    return mix(curve, 12.92 * x, lessThanEqual(x, vec3(0.0031308)));
}

uniform float u_exposure;
uniform int u_tonemap;  // 0 aces, 1 clip

vec4 display(vec3 radiance) {
    vec3 scaled = radiance * exp2(u_exposure);
    vec3 mapped = u_tonemap == 0 ? aces(scaled) : clamp(scaled, 0.0, 1.0);
    return vec4(srgb_encode(mapped), 1.0);
}
"""

#: the sampled lobe: D read from its table, samples placed by its inverse CDF, both as the
#: reference reads them (tests probe it alone; the probe declares u_texture_lod)
SAMPLED_LOBE = """
// ---- D: the table itself (shading_maps: 4 bins a layer of u_distribution), read
// as the reference reads it (matshop.render.brdf.sampled_d)
uniform sampler2DArray u_distribution;
uniform int u_bins;
vec2 g_st;           // this pixel's texture coordinate and its screen derivatives,
vec2 g_st_dx;        // taken in main (uniform control flow) so the table can be read
vec2 g_st_dy;        // inside the lights' loop at the hardware's own level

float bin_d(int k) {
    k = clamp(k, 0, u_bins - 1);
    vec3 at = vec3(g_st, float(k / 4));
    vec4 four = u_texture_lod < 0.0 ? textureGrad(u_distribution, at, g_st_dx, g_st_dy)
                                    : textureLod(u_distribution, at, u_texture_lod);
    return four[k % 4];
}

float bin_edge_x(int k) {
    float s = sin(float(k) * (0.5 * PI) / float(u_bins));
    return s * s;
}

// D at the half vector h: bin k of theta_h keeps exactly its mass, linear in
// x = sin^2 theta about its mean with the smaller slope to its neighbours' means
// (minmod; flat at an extremum and in the end bins), limited so D >= 0 at its ends
float sampled_d(vec3 h) {
    float x = dot(h.xy, h.xy);  // sin^2 theta without 1 - cos^2's cancellation
    int k = clamp(int(atan(sqrt(x), h.z) * float(u_bins) / (0.5 * PI)), 0, u_bins - 1);
    // the bin by its own edges (atan's rounding could put x one bin off them)
    if (k > 0 && x < bin_edge_x(k)) --k;
    if (k < u_bins - 1 && x >= bin_edge_x(k + 1)) ++k;
    float d = bin_d(k);
    float lo = bin_edge_x(k);
    float hi = bin_edge_x(k + 1);
    float mid = 0.5 * (lo + hi);
    float slope = 0.0;
    if (k > 0 && k < u_bins - 1) {
        float left = (d - bin_d(k - 1)) / (mid - 0.5 * (bin_edge_x(k - 1) + lo));
        float right = (bin_d(k + 1) - d) / (0.5 * (hi + bin_edge_x(k + 2)) - mid);
        if (left * right > 0.0) slope = abs(left) < abs(right) ? left : right;
    }
    float limit = 2.0 * abs(d) / (hi - lo);
    return max(d + clamp(slope, -limit, limit) * (x - mid), 0.0);
}

// ---- sampling: the inverse CDF, theta at the 32 of the space's levels around the 16
// samples' u1 (sampled_lobe: the layers after the table's), y = 0 and 1 implied
uniform float u_node_y[32];
float g_theta[34];

float node_y(int k) {
    return k == 0 ? 0.0 : (k == 33 ? 1.0 : u_node_y[k - 1]);
}

void load_nodes() {
    int first = (u_bins + 3) / 4;
    g_theta[0] = 0.0;
    for (int layer = 0; layer < 8; ++layer) {
        vec3 at = vec3(g_st, float(first + layer));
        vec4 four = u_texture_lod < 0.0 ? texture(u_distribution, at)
                                        : textureLod(u_distribution, at, u_texture_lod);
        for (int c = 0; c < 4; ++c) {
            int k = 4 * layer + c;
            // non-monotone texels (filtering, edits) are legal: sort by a running max
            g_theta[k + 1] = clamp(max(four[c], g_theta[k]), 0.0, 0.5 * PI);
        }
    }
    g_theta[33] = 0.5 * PI;
}

// theta(y) linear between the nodes around y, and the pdf per steradian of h from
// that segment's slope (matshop.render.sampling.sample_quantiles)
float sampled_theta(float y, out float pdf) {
    int k = 0;
    while (k < 32 && y >= node_y(k + 1)) ++k;
    float y0 = node_y(k);
    float dy = node_y(k + 1) - y0;
    float lo = g_theta[k];
    float hi = g_theta[k + 1];
    float theta = clamp(lo + (y - y0) / dy * (hi - lo), 0.0, 0.5 * PI - 1e-6);
    pdf = dy / max(hi - lo, 1e-9) / (2.0 * PI * max(sin(theta), 1e-6));  // = D cos theta
    return theta;
}
"""

SURFACE_FRAGMENT = (
    VERSION
    + _COMMON
    + """
in vec3 v_position;
in vec3 v_normal;
in vec4 v_tangent;
in vec2 v_uv;
out vec4 frag_color;

uniform sampler2D u_kd_ao;        // kd (linear), ao
uniform sampler2D u_ks_lobe;      // ks (linear), lobe parameter 0
uniform sampler2D u_normal_lobe;  // tangent-space normal, lobe parameter 1
uniform sampler2D u_tangent;      // tangent-space tangent (when u_has_tangent)
uniform sampler2D u_emissive;     // emissive (when u_has_emissive)
uniform bool u_has_tangent;
uniform bool u_has_emissive;
uniform float u_texture_lod;      // < 0: the hardware's per-pixel level; else this level
uniform int u_family;

uniform sampler2D u_env;          // radiance mip chain (Environment.levels)
uniform sampler2D u_irradiance;   // Environment.irradiance_map
uniform float u_env_texel_solid_angle;
uniform float u_env_scale;
uniform int u_samples;
uniform float u_lod_bias;
uniform bool u_specular;
uniform vec3 u_camera;
uniform int u_light_count;
uniform vec3 u_light_dir[4];      // unit, towards the light
uniform vec3 u_light_irradiance[4];
uniform bool u_linear;            // write the radiance itself (a float target), no display()
uniform bool u_has_base;          // u_base holds this pixel's light-independent radiance:
uniform sampler2D u_base;         // environment and emission, drawn before with u_linear

vec4 material(sampler2D s, vec2 uv) {
    // texture v is up, row 0 (t = 0) is v = 1
    vec2 st = vec2(uv.x, 1.0 - uv.y);
    return u_texture_lod < 0.0 ? texture(s, st) : textureLod(s, st, u_texture_lod);
}

vec3 unit_or_z(vec3 v) {
    float len = length(v);
    return len > 1e-8 ? v / len : vec3(0.0, 0.0, 1.0);
}

"""
    + SAMPLED_LOBE
    + """
// ---- D(h), normalised over the projected hemisphere (matshop.render.brdf)
float distribution(vec3 h, vec2 p) {
    if (h.z <= 0.0) return 0.0;
    if (u_family == 4) return sampled_d(h);
    float c2 = h.z * h.z;
    float s2 = max(1.0 - c2, 0.0);
    if (u_family == 0) {
        float a2 = p.x * p.x;
        float q = a2 * c2 + s2;
        return a2 / (PI * q * q);
    } else if (u_family == 1) {
        float m2 = p.x * p.x;
        return exp(-(s2 / c2) / m2) / (PI * m2 * c2 * c2);
    } else if (u_family == 2) {
        return (p.x + 2.0) / (2.0 * PI) * pow(h.z, p.x);
    }
    float e = s2 > 1e-12 ? (p.x * h.x * h.x + p.y * h.y * h.y) / s2 : 0.5 * (p.x + p.y);
    return sqrt((p.x + 2.0) * (p.y + 2.0)) / (2.0 * PI) * pow(h.z, e);
}

float cook_torrance_g(float n_h, float n_o, float n_i, float o_h) {
    float inv = 2.0 * max(n_h, 0.0) / max(o_h, EPS);
    return clamp(min(inv * n_o, inv * n_i), 0.0, 1.0);
}

vec3 brdf(vec3 i, vec3 o, vec3 kd, vec3 ks, vec2 p) {
    if (i.z <= 0.0 || o.z <= 0.0) return vec3(0.0);
    vec3 h = i + o;
    h /= max(length(h), EPS);
    float o_h = dot(o, h);
    float m = clamp(1.0 - o_h, 0.0, 1.0);
    vec3 f = ks + (1.0 - ks) * (m * m) * (m * m) * m;
    float dg = distribution(h, p) * cook_torrance_g(h.z, o.z, i.z, o_h);
    return kd / PI + f * (dg / (4.0 * max(i.z, EPS) * max(o.z, EPS)));
}

// ---- importance sampling of h (matshop.render.sampling): returns h, sets pdf per sr
vec2 hammersley(int j, int n) {
    uint bits = uint(j);
    bits = (bits << 16u) | (bits >> 16u);
    bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
    bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
    bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
    bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
    return vec2((float(j) + 0.5) / float(n), float(bits) * 2.3283064365386963e-10);
}

vec3 from_tan2(float tan2, float u2, out float cos2) {
    cos2 = 1.0 / (1.0 + tan2);
    float sin_t = sqrt(clamp(tan2 * cos2, 0.0, 1.0));  // = sqrt(1 - cos2), without cancellation
    float phi = 2.0 * PI * u2;
    return vec3(sin_t * cos(phi), sin_t * sin(phi), sqrt(cos2));
}

vec3 sample_lobe(vec2 u, vec2 p, out float pdf) {
    float y = u.x;
    float cos2;
    if (u_family == 4) {
        float theta = sampled_theta(y, pdf);
        float phi = 2.0 * PI * u.y;
        return vec3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
    }
    if (u_family == 0) {
        float a2 = p.x * p.x;
        vec3 h = from_tan2(a2 * (y / (1.0 - y)), u.y, cos2);
        float q = a2 * cos2 + (1.0 - cos2);
        pdf = a2 / (PI * q * q) * h.z;
        return h;
    } else if (u_family == 1) {
        float m2 = p.x * p.x;
        float tan2 = -m2 * log(1.0 - y);
        vec3 h = from_tan2(tan2, u.y, cos2);
        pdf = exp(-tan2 / m2) / (PI * m2 * cos2 * cos2) * h.z;
        return h;
    } else if (u_family == 2) {
        float cos_t = clamp(pow(1.0 - y, 1.0 / (p.x + 2.0)), 1e-6, 1.0);
        vec3 h = from_tan2(1.0 / (cos_t * cos_t) - 1.0, u.y, cos2);
        pdf = (p.x + 2.0) / (2.0 * PI) * pow(cos_t, p.x + 1.0);
        return h;
    }
    // Ashikhmin-Shirley: azimuth by quadrant, then theta from the azimuth's exponent
    float quarter = floor(4.0 * u.y);
    float psi = clamp(4.0 * u.y - quarter, 1e-6, 1.0 - 1e-6) * 0.5 * PI;
    float phi = atan(sqrt((p.x + 2.0) / (p.y + 2.0)) * tan(psi));
    if (quarter == 1.0) phi = PI - phi;
    else if (quarter == 2.0) phi = PI + phi;
    else if (quarter == 3.0) phi = 2.0 * PI - phi;
    float e = p.x * cos(phi) * cos(phi) + p.y * sin(phi) * sin(phi);
    float cos_t = clamp(pow(1.0 - y, 1.0 / (e + 2.0)), 1e-6, 1.0);
    float sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0));
    vec3 h = vec3(sin_t * cos(phi), sin_t * sin(phi), cos_t);
    pdf = distribution(h, p) * h.z;
    return h;
}

vec3 environment_specular(vec3 o, mat3 frame, vec3 ks, vec2 p) {
    vec3 s0 = vec3(0.0);
    vec3 s5 = vec3(0.0);
    float widen = 1.0;
    if (u_family == 3) {
        // samples of a stretched lobe lie further apart along its long axis
        float a = p.x + 2.0;
        float b = p.y + 2.0;
        widen = sqrt(max(a, b) / min(a, b));
    }
    for (int j = 0; j < u_samples; ++j) {
        float pdf;
        vec3 h = sample_lobe(hammersley(j, u_samples), p, pdf);
        float o_h = dot(o, h);
        vec3 i = 2.0 * o_h * h - o;
        if (i.z <= 0.0 || o_h <= 0.0) continue;
        float g = cook_torrance_g(h.z, o.z, i.z, o_h);
        float weight = g * o_h / (o.z * max(h.z, EPS));
        float m = clamp(1.0 - o_h, 0.0, 1.0);
        float m5 = (m * m) * (m * m) * m;
        float omega = 4.0 * max(o_h, EPS) / (float(u_samples) * max(pdf, 1e-12)) * widen;
        float lod = 0.5 * log2(max(omega / u_env_texel_solid_angle, 1.0)) + u_lod_bias;
        vec3 radiance = textureLod(u_env, direction_to_uv(frame * i), lod).rgb;
        s0 += weight * radiance;
        s5 += weight * m5 * radiance;
    }
    float n = float(u_samples);
    return ks * (s0 / n) + (1.0 - ks) * (s5 / n);
}

void main() {
    // geometric frame, orthonormalised after interpolation; two-sided like the reference
    vec3 gn = normalize(v_normal);
    if (!gl_FrontFacing) gn = -gn;
    vec3 gt = v_tangent.xyz - gn * dot(gn, v_tangent.xyz);
    vec3 side = abs(gn.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    gt = length(gt) > 1e-8 ? normalize(gt) : normalize(cross(side, gn));
    vec3 gb = cross(gn, gt) * (v_tangent.w < 0.0 ? -1.0 : 1.0);

    vec4 kd_ao = material(u_kd_ao, v_uv);
    vec4 ks_lobe = material(u_ks_lobe, v_uv);
    vec4 normal_lobe = material(u_normal_lobe, v_uv);
    vec3 kd = kd_ao.rgb;
    vec3 ks = ks_lobe.rgb;
    vec2 lobe = vec2(ks_lobe.a, normal_lobe.a);
    g_st = vec2(v_uv.x, 1.0 - v_uv.y);
    g_st_dx = dFdx(g_st);
    g_st_dy = dFdy(g_st);
    if (u_family == 4) load_nodes();

    // shading frame (matshop.render.integrator.shading_frame)
    vec3 nl = unit_or_z(normal_lobe.xyz);
    vec3 n = normalize(gt * nl.x + gb * nl.y + gn * nl.z);
    vec3 t = gt;
    if (u_has_tangent) {
        vec3 tl = unit_or_z(material(u_tangent, v_uv).xyz);
        t = gt * tl.x + gb * tl.y + gn * tl.z;
    }
    t = t - n * dot(t, n);
    t /= max(length(t), 1e-12);
    vec3 b = cross(n, t);
    mat3 frame = mat3(t, b, n);  // local -> world

    vec3 view = normalize(u_camera - v_position);
    vec3 o = view * frame;  // world -> local (transpose)
    o.z = max(o.z, 1e-3);
    o = normalize(o);

    vec3 radiance = vec3(0.0);
    if (u_has_base) {
        radiance = texelFetch(u_base, ivec2(gl_FragCoord.xy), 0).rgb;
    } else {
        if (u_env_scale != 0.0) {
            if (u_specular) radiance += u_env_scale * environment_specular(o, frame, ks, lobe);
            vec3 e = texture(u_irradiance, direction_to_uv(n)).rgb * kd_ao.a;
            radiance += u_env_scale * kd / PI * e;
        }
        if (u_has_emissive) radiance += material(u_emissive, v_uv).rgb;
    }
    for (int k = 0; k < u_light_count; ++k) {
        vec3 i = u_light_dir[k] * frame;
        vec3 rho = u_specular ? brdf(i, o, kd, ks, lobe) : kd / PI;
        radiance += rho * max(i.z, 0.0) * u_light_irradiance[k];
    }
    frag_color = u_linear ? vec4(radiance, 1.0) : display(radiance);
}
"""
)

# The background: a full-screen triangle; every pixel looks the environment up
# along its camera ray at level 2 (the reference's blurred backdrop).
BACKGROUND_VERTEX = (
    VERSION
    + """
out vec2 v_ndc;
void main() {
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2) * 2.0 - 1.0;
    v_ndc = p;
    gl_Position = vec4(p, 1.0, 1.0);
}
"""
)

BACKGROUND_FRAGMENT = (
    VERSION
    + _COMMON
    + """
in vec2 v_ndc;
out vec4 frag_color;
uniform mat3 u_camera_to_world;
uniform vec2 u_tan_half_fov;  // x, y
uniform sampler2D u_env;
uniform float u_background_lod;
uniform bool u_flat_background;
uniform vec3 u_background;
void main() {
    if (u_flat_background) {
        frag_color = display(u_background);
        return;
    }
    vec3 ray = normalize(u_camera_to_world * vec3(v_ndc * u_tan_half_fov, -1.0));
    frag_color = display(textureLod(u_env, direction_to_uv(ray), u_background_lod).rgb);
}
"""
)

# The picking pass: texture coordinates (after the uv scale) and the world
# position and normal of the nearest surface under every pixel, in float.
PICK_FRAGMENT = (
    VERSION
    + """
in vec3 v_position;
in vec3 v_normal;
in vec4 v_tangent;
in vec2 v_uv;
layout(location = 0) out vec4 out_uv;
layout(location = 1) out vec4 out_position;
layout(location = 2) out vec4 out_normal;
void main() {
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;
    out_uv = vec4(v_uv, 1.0, 0.0);
    out_position = vec4(v_position, 1.0);
    out_normal = vec4(n, 1.0);
}
"""
)

# The UV-space bake: the mesh drawn with its texture coordinates as positions,
# so every texel centre receives the surface point, normal and texel size there.
BAKE_VERTEX = (
    VERSION
    + """
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in float a_texel_world;
layout(location = 3) in vec2 a_uv;
uniform vec2 u_offset;  // minus the integer uv cell being baked
out vec3 v_position;
out vec3 v_normal;
out float v_texel_world;
void main() {
    v_position = a_position;
    v_normal = a_normal;
    v_texel_world = a_texel_world;
    vec2 uv = a_uv + u_offset;
    // texel row 0 is v = 1: put it at the bottom of the framebuffer, read back first
    gl_Position = vec4(uv.x * 2.0 - 1.0, (1.0 - uv.y) * 2.0 - 1.0, 0.0, 1.0);
}
"""
)

BAKE_FRAGMENT = (
    VERSION
    + """
in vec3 v_position;
in vec3 v_normal;
in float v_texel_world;
layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;
void main() {
    out_position = vec4(v_position, v_texel_world);
    out_normal = vec4(normalize(v_normal), 1.0);
}
"""
)


def specialised(fragment: str, family: str) -> str:
    """``fragment`` with its D family fixed when it compiles (``u_family`` a constant).

    The compiler then drops the other families' code, which a CPU driver otherwise
    pays for on every pixel: llvmpipe (Mesa 22.3) draws the surface shader of a GGX
    material 2.2x faster (1024^2 swatch: 2.0 s -> 0.9 s under load). For a view that
    shows one document's material at a time (the lit swatch).
    """
    declaration = "uniform int u_family;"
    if declaration not in fragment:
        raise ValueError("the fragment shader declares no 'uniform int u_family;'")
    return fragment.replace(declaration, f"const int u_family = {FAMILY_CODES[family]};")


class ShaderError(RuntimeError):
    """A shader failed to compile or link (the driver's log is in the message)."""


def _compile(kind: int, source: str) -> int:
    shader = GL.glCreateShader(kind)
    GL.glShaderSource(shader, source)
    GL.glCompileShader(shader)
    if not GL.glGetShaderiv(shader, GL.GL_COMPILE_STATUS):
        log = GL.glGetShaderInfoLog(shader)
        GL.glDeleteShader(shader)
        raise ShaderError(log.decode(errors="replace") if isinstance(log, bytes) else str(log))
    return shader


class Program:
    """A linked vertex + fragment program with cached uniform locations."""

    def __init__(self, vertex: str, fragment: str) -> None:
        shaders = [_compile(GL.GL_VERTEX_SHADER, vertex), _compile(GL.GL_FRAGMENT_SHADER, fragment)]
        self.id = GL.glCreateProgram()
        for shader in shaders:
            GL.glAttachShader(self.id, shader)
        GL.glLinkProgram(self.id)
        for shader in shaders:
            GL.glDeleteShader(shader)
        if not GL.glGetProgramiv(self.id, GL.GL_LINK_STATUS):
            log = GL.glGetProgramInfoLog(self.id)
            raise ShaderError(log.decode(errors="replace") if isinstance(log, bytes) else str(log))
        self._locations: dict[str, int] = {}

    def use(self) -> None:
        GL.glUseProgram(self.id)

    def location(self, name: str) -> int:
        if name not in self._locations:
            self._locations[name] = GL.glGetUniformLocation(self.id, name)
        return self._locations[name]

    def set(self, name: str, value: object) -> None:
        """Set a uniform by its Python value: bool/int, float, vec2-4, mat3/mat4, vec3 arrays."""
        loc = self.location(name)
        if loc < 0:
            return  # optimised away: not an error
        if isinstance(value, bool | np.bool_) or isinstance(value, int | np.integer):
            GL.glUniform1i(loc, int(value))
            return
        if isinstance(value, float | np.floating):
            GL.glUniform1f(loc, float(value))
            return
        array = np.asarray(value, dtype=np.float32)
        if array.shape == (4, 4):
            GL.glUniformMatrix4fv(loc, 1, GL.GL_TRUE, array)
        elif array.shape == (3, 3):
            GL.glUniformMatrix3fv(loc, 1, GL.GL_TRUE, array)
        elif array.ndim == 2 and array.shape[1] == 3:
            GL.glUniform3fv(loc, array.shape[0], array)
        elif array.shape == (2,):
            GL.glUniform2fv(loc, 1, array)
        elif array.shape == (3,):
            GL.glUniform3fv(loc, 1, array)
        elif array.shape == (4,):
            GL.glUniform4fv(loc, 1, array)
        else:
            raise ValueError(f"uniform {name}: unsupported value shape {array.shape}")

    def set_floats(self, name: str, values: np.ndarray) -> None:
        """Set a ``float name[n]`` uniform array."""
        loc = self.location(name)
        if loc >= 0:
            flat = np.ascontiguousarray(values, dtype=np.float32).ravel()
            GL.glUniform1fv(loc, flat.size, flat)

    def delete(self) -> None:
        GL.glDeleteProgram(self.id)
