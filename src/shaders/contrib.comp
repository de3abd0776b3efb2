// rcontrib's estimator on the GPU: the same ray tree as src/raytrace/contrib.cpp (rayorigin's
// weights and Russian roulette, n x n stratified cosine hemispheres with RADIANCE's collision
// rule, Fresnel-estimated plastic and metal, trans, glass, mirror, glow, distant light sources
// with shadow rays, their images in mirrors), walked with an explicit stack since GLSL has no
// recursion.
//
// The host prepends: #version and extensions, the constants below as #defines, common.h, the
// generated calcomp functions and EvalBin(j), which runs bin function j:
//   AB AD LW LR NCOLS IRRADIANCE FIRST_HIT CONTRIBUTIONS NSOURCES DJ SEED TMIN
//   CENTRE_X CENTRE_Y CENTRE_Z MAXN LOCAL_SIZE STACK_SIZE ACCUM_T (float or double)

layout(local_size_x = LOCAL_SIZE) in;
#ifdef DAYFLUX_BVH
layout(std430, set = 0, binding = 0) readonly buffer Bvh { GpuBvhNode bvh_nodes[]; };
layout(std430, set = 0, binding = kBindingBvhPrims) readonly buffer BvhPrims { int bvh_prims[]; };
#else
layout(set = 0, binding = 0) uniform accelerationStructureEXT scene;
#endif
layout(std430, set = 0, binding = kBindingRays) readonly buffer Rays { vec4 rays[]; };
layout(std430, set = 0, binding = kBindingPositions) readonly buffer Positions { float positions[]; };
layout(std430, set = 0, binding = kBindingIndices) readonly buffer Indices { uint indices[]; };
layout(std430, set = 0, binding = kBindingTriangles) readonly buffer Triangles { GpuTriangle triangles[]; };
layout(std430, set = 0, binding = kBindingSurfaces) readonly buffer Surfaces { GpuSurface surfaces[]; };
layout(std430, set = 0, binding = kBindingSources) readonly buffer Sources { GpuSource sources[]; };
layout(std430, set = 0, binding = kBindingAccum) buffer Accum { ACCUM_T accum[]; };
layout(std430, set = 0, binding = kBindingTasks) readonly buffer Tasks { GpuTasks tasks; };
layout(std430, set = 0, binding = kBindingStats) buffer Stats { uint stats_dropped; };
layout(std430, set = 0, binding = kBindingShapes) readonly buffer Shapes { GpuShape shapes[]; };
layout(std430, set = 0, binding = kBindingRelays) readonly buffer Relays { vec4 relays[]; };
layout(std430, set = 0, binding = kBindingTracked) readonly buffer Tracked { ivec4 tracked[]; };

const float kTiny = 1e-6;  // RADIANCE's FTINY
const float kPi = 3.14159265358979;
const float kFresnelThreshold = 0.017999;

// Ray types as RADIANCE's ray.h numbers them.
const int kPrimary = 1, kShadow = 2, kReflected = 4, kRefracted = 8, kTrans = 16, kAmbient = 32,
          kSpecular = 64;
const int kReflectionTypes = kShadow | kReflected | kAmbient | kSpecular;

// ---- random numbers: counter-based (PCG hash), so a cell's draws can be replayed anywhere.
uint Pcg(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}
uint Key(uint a, uint b, uint c, uint d) { return Pcg(a ^ Pcg(b ^ Pcg(c ^ Pcg(d)))); }
uint rng;
uint cell_key;  // the path's random numbers: key of the input ray, then of the cell
float Rand() {
    rng = Pcg(rng);
    return float(rng >> 8) * (1.0 / 16777216.0);
}

float Max3(vec3 c) { return max(c.x, max(c.y, c.z)); }
float Bright(vec3 c) { return dot(c, vec3(0.2651058, 0.6701058, 0.0647884)); }
float FresnelEstimate(float cosi) { return exp(-5.85 * cosi) - 0.00287989916; }

void Tangents(vec3 n, out vec3 u, out vec3 v) {
    vec3 e = abs(n.x) < 0.6 ? vec3(1, 0, 0) : (abs(n.y) < 0.6 ? vec3(0, 1, 0) : vec3(0, 0, 1));
    u = normalize(cross(e, n));
    v = cross(n, u);
}

// RADIANCE's getperpendicular() with randomize on (raytrace/materials.h's RandomTangents()):
// a tangent turned by a random amount about n, for ambient hemispheres.
vec3 RandomTangent(vec3 n, float r0, float r1, float r2, float r3) {
    vec3 e = vec3(0.5 - r0, 0.5 - r1, 0.5 - r2);
    int o = min(5, int(r3 * 6.));
    ivec3 ord = o == 0 ? ivec3(0, 1, 2) : o == 1 ? ivec3(0, 2, 1) : o == 2 ? ivec3(1, 0, 2)
              : o == 3 ? ivec3(1, 2, 0) : o == 4 ? ivec3(2, 0, 1) : ivec3(2, 1, 0);
    int i = 2;
    while (i > 0 && !(abs(n[ord[i]]) < 0.6)) --i;
    e[ord[i]] = 1.0;
    return normalize(cross(e, n));
}

// Shirley-Chiu square to disk (RADIANCE's square2disk()).
vec2 SquareToDisk(float sx, float sy) {
    float a = 2 * sx - 1, b = 2 * sy - 1, r, phi;
    if (a > -b) {
        if (a > b) { r = a; phi = kPi / 4 * (b / a); }
        else { r = b; phi = kPi / 4 * (2 - a / b); }
    } else {
        if (a < b) { r = -a; phi = kPi / 4 * (4 + b / a); }
        else { r = -b; phi = b != 0 ? kPi / 4 * (6 - a / b) : 0; }
    }
    return vec2(r * cos(phi), r * sin(phi));
}

// ---- the ray stack
const int kItemTrace = 0, kItemAmbient = 1, kItemDirect = 2, kItemDirectBsdf = 3;
struct Ray {
    vec3 org, dir;
    vec3 coef;    // product of the coefficients from the input ray down to this ray
    float weight; // RADIANCE's rweight
    int rlvl, crtype, adepth, aimed;
    int depth;    // rays above it in the tree (the CPU integrator's guard against loops)
    int from;     // the object it leaves (-1: none), which it does not meet again where it starts
    uint clip;    // antimatter bits of the modifiers it passes unseen (RADIANCE's clipset)
#ifdef ASUB
    float dscale; // -asub: what the diffuse paths it starts are multiplied by (1, 0 or ASUB^2)
#endif
#ifdef DAYFLUX_DIELECTRIC
    vec3 cext;    // extinction of the medium it travels in (rayorigin() weighs children by it)
    float t;      // its length, where a dielectric set it
#endif
};
const int kMaxDepth = 200;
struct Item {
    Ray r;
    int kind;
    // kItemAmbient: a hemisphere about normal at point, cells next .. cells_end in RADIANCE's
    // order (i, j from n - 1 down); kItemDirect: sources next .. NSOURCES - 1.
    vec3 point, normal, colour;  // colour: the hemisphere's coefficient (already / n^2), or the
                                 // surface colour for the direct part
    float rdiff, tdiff, trans;
    int n, next, end, fresnel;
    vec3 spec, incident;  // kItemDirect: rough specular colour and the ray's direction;
                          // kItemAmbient: incident holds the hemisphere's (turned) tangent
    float alpha2;         // kItemDirect: its roughness squared (0: none)
    int part;             // kItemDirect*: the part of local source `next` sampled next
    uint turn;            // kItemDirect*: keys the random turn of local sources' squares
};
Item stack[STACK_SIZE];
int top = 0;
uint dropped = 0;
void Push(Item it) {
    if (top < STACK_SIZE) stack[top++] = it; else ++dropped;
}

// ---- where this task's results go
uint acc_base;
// The ray variables $1..$27 (rayinit.cal) for the bins and patterns: direction, normal, point
// (world), distance, Rdot, scale, identity transform.
void SetRayVariables(Ray r, vec3 point, vec3 normal, float t) {
    cal_chan[1] = r.dir.x; cal_chan[2] = r.dir.y; cal_chan[3] = r.dir.z;
    cal_chan[4] = normal.x; cal_chan[5] = normal.y; cal_chan[6] = normal.z;
    cal_chan[7] = double(point.x) + CENTRE_X;
    cal_chan[8] = double(point.y) + CENTRE_Y;
    cal_chan[9] = double(point.z) + CENTRE_Z;
    cal_chan[10] = t;
    cal_chan[11] = -dot(r.dir, normal);
    cal_chan[12] = 1;
    for (int i = 13; i <= 27; ++i) cal_chan[i] = 0;
    cal_chan[16] = 1; cal_chan[20] = 1; cal_chan[24] = 1;
}

// A material's colour at a hit, times its pattern.
vec3 Colour(GpuSurface m, Ray r, vec3 point, vec3 normal, float t) {
    if (m.pattern < 0) return m.color.rgb;
    SetRayVariables(r, point, normal, t);
    return m.color.rgb * PatternRGB(m.pattern);
}

void Contribute(int k, Ray r, vec3 point, vec3 normal, float t, vec3 radiance) {
    SetRayVariables(r, point, normal, t);
    ivec4 mod = tracked[k];  // first column, bins, bin function
    double b = EvalBin(mod.z);
    if (b < -0.5) return;
    int bin = int(floor(b + 0.5));
    if (bin >= mod.y) return;
    uint at = acc_base + 3u * uint(mod.x + bin);
    vec3 v = CONTRIBUTIONS != 0 ? r.coef * radiance : r.coef;
    accum[at] += ACCUM_T(v.x);
    accum[at + 1] += ACCUM_T(v.y);
    accum[at + 2] += ACCUM_T(v.z);
}

// rayorigin(): the child's coefficient and weight, Russian roulette. False if it dies.
bool Spawn(Ray parent, int type, vec3 rc, out Ray child) {
    float rw = min(1.0, Max3(rc));
    child = parent;
    child.depth = parent.depth + 1;
    child.rlvl = parent.rlvl + ((type & kReflectionTypes) != 0 ? 1 : 0);
    child.crtype = parent.crtype | type;
    child.weight = parent.weight * rw;
    child.coef = parent.coef * rc;
    child.aimed = (type & kReflectionTypes) != 0 ? -1 : parent.aimed;
#ifdef DAYFLUX_DIELECTRIC
    child.t = 0;
    float re = min(parent.cext.x, min(parent.cext.y, parent.cext.z)) * parent.t;
    if (re > 0.1) child.weight = re > 92.0 ? 0.0 : child.weight * exp(-re);
#endif
    if (child.weight <= 0) return false;
    if ((child.crtype & kShadow) != 0) return true;
    if (LR <= 0) {
        if (LR < 0 && child.rlvl > -LR) return false;
        if (child.weight >= LW) return true;
        if (Rand() > child.weight / LW) return false;
        child.coef *= float(LW) / child.weight;
        child.weight = float(LW);
        return true;
    }
    return child.weight >= LW && child.rlvl <= LR;
}

// ---- tracing
vec3 Vertex(uint i) { return vec3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]); }

// The point of triangle abc closest to p (the CPU backend's refinement: new rays never start
// outside a closed room).
vec3 ClosestPointOnTriangle(vec3 p, vec3 a, vec3 b, vec3 c) {
    vec3 ab = b - a, ac = c - a, ap = p - a;
    float d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return a;
    vec3 bp = p - b;
    float d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return b;
    float vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
    vec3 cp = p - c;
    float d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return c;
    float vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
    float va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
        return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    float denom = 1 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

// ---- analytic surfaces (raytrace/analytic.cpp in float, on recentred coordinates)
bool Quadratic(float a, float b, float c, out float t0, out float t1) {
    if (abs(a) < 1e-30) {
        if (abs(b) < 1e-30) return false;
        t0 = t1 = -c / b;
        return true;
    }
    float disc = b * b - 4 * a * c;
    if (disc < 0) return false;
    float q = -0.5 * (b + (b < 0 ? -sqrt(disc) : sqrt(disc)));
    float x0 = q / a, x1 = q != 0 ? c / q : x0;
    t0 = min(x0, x1);
    t1 = max(x0, x1);
    return true;
}

// The nearest t in (tmin, tmax) where the ray meets shape s, or -1.
float IntersectShape(GpuShape s, vec3 org, vec3 dir, float tmin, float tmax) {
    float t0, t1;
    if (s.kind == kShapeSphere) {
        vec3 oc = org - s.p0.xyz;
        if (!Quadratic(1.0, 2 * dot(oc, dir), dot(oc, oc) - s.p0.w * s.p0.w, t0, t1)) return -1;
        if (t0 > tmin && t0 < tmax) return t0;
        if (t1 > tmin && t1 < tmax) return t1;
        return -1;
    }
    if (s.kind == kShapeRing) {
        vec3 n = normalize(s.p1.xyz);
        float dn = dot(dir, n);
        if (abs(dn) < 1e-30) return -1;
        float t = dot(s.p0.xyz - org, n) / dn;
        if (!(t > tmin && t < tmax)) return -1;
        vec3 x = org + t * dir - s.p0.xyz;
        float r2 = dot(x, x);
        return r2 >= s.p0.w * s.p0.w && r2 <= s.p1.w * s.p1.w ? t : -1;
    }
    // cone, cylinder: |wp + t dp|^2 = (r0 + slope (wu + t du))^2 along the axis
    vec3 d = s.p1.xyz - s.p0.xyz;
    float len = length(d);
    vec3 u = d / len;
    float slope = (s.p1.w - s.p0.w) / len;
    vec3 w = org - s.p0.xyz;
    float wu = dot(w, u), du = dot(dir, u);
    vec3 wp = w - wu * u, dp = dir - du * u;
    float rw = s.p0.w + slope * wu, rd = slope * du;
    if (!Quadratic(dot(dp, dp) - rd * rd, 2 * (dot(wp, dp) - rw * rd), dot(wp, wp) - rw * rw, t0,
                   t1))
        return -1;
    for (int k = 0; k < 2; ++k) {
        float t = k == 0 ? t0 : t1;
        if (!(t > tmin && t < tmax)) continue;
        float z = wu + t * du;
        if (z < 0 || z > len || s.p0.w + slope * z < 0) continue;
        return t;
    }
    return -1;
}

// The unit normal at p on shape s (outward; inward for bubble, cup, tube).
vec3 ShapeNormal(GpuShape s, vec3 p) {
    vec3 n;
    if (s.kind == kShapeSphere) {
        n = p - s.p0.xyz;
    } else if (s.kind == kShapeRing) {
        n = s.p1.xyz;
    } else {
        vec3 d = s.p1.xyz - s.p0.xyz;
        float len = length(d);
        vec3 u = d / len;
        float slope = (s.p1.w - s.p0.w) / len;
        vec3 w = p - s.p0.xyz;
        vec3 radial = w - dot(w, u) * u;
        float rl = length(radial);
        n = (rl > 0 ? radial / rl : vec3(0)) - slope * u;
    }
    n = normalize(n);
    return s.inward != 0 ? -n : n;
}

// Rays leaving a surface (from >= 0) meet every other surface from the start and their own
// object not at all where they start (a polygon never: it is planar; a mesh or analytic surface
// not before TMIN), as the CPU backend's filter has it; other rays start TMIN off.
float StartOf(int from) { return from >= 0 ? 1e-3 * TMIN : TMIN; }
bool OwnTriangle(int p, int from, float t) {
    return triangles[p].object == from && (triangles[p].mesh == 0 || t < TMIN);
}
float ShapeStart(int s, int from) { return shapes[s].object == from ? TMIN : StartOf(from); }

#ifdef DAYFLUX_BVH
// Moller-Trumbore, with a hair of slack at the edges so that rays do not slip between
// triangles sharing one (the hit is moved into its triangle afterwards).
float IntersectTriangle(int p, vec3 org, vec3 dir, float tmin, float tmax) {
    vec3 a = Vertex(indices[3 * p]), b = Vertex(indices[3 * p + 1]), c = Vertex(indices[3 * p + 2]);
    vec3 e1 = b - a, e2 = c - a, pv = cross(dir, e2);
    float det = dot(e1, pv);
    if (det == 0) return -1;
    float inv = 1.0 / det;
    vec3 tv = org - a;
    float u = dot(tv, pv) * inv;
    if (u < -1e-6 || u > 1 + 1e-6) return -1;
    vec3 q = cross(tv, e1);
    float v = dot(dir, q) * inv;
    if (v < -1e-6 || u + v > 1 + 1e-6) return -1;
    float t = dot(e2, q) * inv;
    return t > tmin && t < tmax ? t : -1;
}

// The nearest hit: a triangle (shape < 0) or an analytic surface, by walking our BVH (no ray
// queries on this device). Leaf entries are triangles, or -(shape + 1).
bool Closest(vec3 org, vec3 dir, int from, out float t, out int prim, out int shape) {
    t = 1e30;
    prim = -1;
    shape = -1;
    if (bvh_nodes.length() == 0) return false;
    float tmin = StartOf(from);
    vec3 safe = mix(vec3(1e-20), -vec3(1e-20), lessThan(dir, vec3(0)));
    vec3 inv = 1.0 / mix(dir, safe, lessThan(abs(dir), vec3(1e-20)));
    int stack[64];
    int sp = 0, node = 0;
    while (true) {
        GpuBvhNode n = bvh_nodes[node];
        vec3 t0 = (n.lo.xyz - org) * inv, t1 = (n.hi.xyz - org) * inv;
        vec3 tn = min(t0, t1), tf = max(t0, t1);
        float enter = max(max(tn.x, tn.y), max(tn.z, tmin));
        float leave = min(min(tf.x, tf.y), min(tf.z, t));
        if (enter <= leave * 1.000001) {
            if (n.count == 0) {
                if (sp < 64) stack[sp++] = n.index;
                node = node + 1;
                continue;
            }
            for (int i = 0; i < n.count; ++i) {
                int p = bvh_prims[n.index + i];
                if (p >= 0) {
                    float th = IntersectTriangle(p, org, dir, tmin, t);
                    if (th > 0 && !OwnTriangle(p, from, th)) { t = th; prim = p; shape = -1; }
                } else {
                    float th = IntersectShape(shapes[-p - 1], org, dir, ShapeStart(-p - 1, from), t);
                    if (th >= 0 && th < t) { t = th; prim = -p - 1; shape = prim; }
                }
            }
        }
        if (sp == 0) break;
        node = stack[--sp];
    }
    return prim >= 0;
}
#else
// The nearest hit: a triangle (shape < 0) or an analytic surface.
// Triangles are opaque (no candidates to filter), so a ray that meets its own object where it
// starts is cast again from beyond that point, from further off each time (at last TMIN).
bool Closest(vec3 org, vec3 dir, int from, out float t, out int prim, out int shape) {
    float tmin = StartOf(from);
    for (int attempt = 0; attempt < 4; ++attempt) {
        rayQueryEXT q;
        rayQueryInitializeEXT(q, scene, gl_RayFlagsOpaqueEXT, 0xFF, org, tmin, dir, 1e30);
        while (rayQueryProceedEXT(q)) {
            if (rayQueryGetIntersectionTypeEXT(q, false) !=
                gl_RayQueryCandidateIntersectionAABBEXT)
                continue;
            float tmax = rayQueryGetIntersectionTypeEXT(q, true) !=
                                 gl_RayQueryCommittedIntersectionNoneEXT
                             ? rayQueryGetIntersectionTEXT(q, true)
                             : 1e30;
            int s = rayQueryGetIntersectionPrimitiveIndexEXT(q, false);
            float th = IntersectShape(shapes[s], org, dir, max(tmin, ShapeStart(s, from)), tmax);
            if (th >= 0) rayQueryGenerateIntersectionEXT(q, th);
        }
        uint type = rayQueryGetIntersectionTypeEXT(q, true);
        if (type == gl_RayQueryCommittedIntersectionNoneEXT) return false;
        t = rayQueryGetIntersectionTEXT(q, true);
        prim = rayQueryGetIntersectionPrimitiveIndexEXT(q, true);
        shape = type == gl_RayQueryCommittedIntersectionGeneratedEXT ? prim : -1;
        if (shape >= 0 || attempt == 3 || !OwnTriangle(prim, from, t)) return true;
        tmin = attempt == 2 ? max(2. * t, TMIN) : max(2. * t, 10. * tmin);
    }
    return false;
}
#endif

void ShadeMaterial(Ray r, int object, GpuSurface m, vec3 point, vec3 normal, float rod, float t);
void PushChild(Ray r, int type, vec3 coef, vec3 org, vec3 dir);

// A ray reaches something (tracked modifier k, material m); normal faces the ray afterwards.
bool hit_front;  // whether the ray being shaded met its surface's front (BSDF frames need it)

// m_clip(): entering antimatter adds its modifiers to the ray's clip set, leaving removes them.
void PassAntimatter(Ray r, GpuSurface m, vec3 point) {
    uint bits = uint(m.fore);
    r.clip = hit_front ? r.clip | bits : r.clip & ~bits;
    PushChild(r, kTrans, vec3(1), point, r.dir);
}

void Shade(Ray r, int object, int k, GpuSurface m, vec3 point, vec3 geo_normal, float t) {
    r.from = object;  // the rays it spawns leave this object
    float rod = -dot(r.dir, geo_normal);
    hit_front = rod > 0;
    vec3 normal = rod < 0 ? -geo_normal : geo_normal;
    rod = abs(rod);
    bool aimed_elsewhere = r.aimed >= 0 && object != sources[r.aimed].object;
    if (aimed_elsewhere) k = -1;
    bool light = m.kind == kMatLight || m.kind == kMatIllum;
    if (light) {
        // m_light() (as the CPU integrator's Shade()): ambient and specular rays meeting a light's
        // front count nothing; a shadow ray aimed elsewhere stops, unless at an illum it may
        // pass; a shadow ray meeting its source from behind counts nothing; an illum passes the
        // rays not aimed at it to its alternate material.
        bool shadow = (r.crtype & kShadow) != 0;
        if ((r.crtype & (kAmbient | kSpecular)) != 0 && !shadow && hit_front) return;
        if (aimed_elsewhere &&
            (m.kind != kMatIllum ||
             (hit_front && (int(sources[r.aimed].v.w) & kSourceWeak) != 0)))
            return;
        if (shadow && r.aimed >= 0 && !aimed_elsewhere && !hit_front) return;
        bool pass = m.kind == kMatIllum && (r.aimed < 0 || aimed_elsewhere);
        if (k >= 0) {
            bool lit = !pass && hit_front &&
                       !(m.alpha2 > 0 && m.alpha2 < 2. * kPi * (1. + dot(m.params.xyz, r.dir)));
            Contribute(k, r, point, normal, t,
                       CONTRIBUTIONS == 0 ? vec3(1)
                       : lit              ? Colour(m, r, point, normal, t)
                                          : vec3(0));
        }
        if (!pass) return;
        if (m.fore < 0) {
            PushChild(r, kTrans, vec3(1), point, r.dir);
            return;
        }
        m = surfaces[m.fore];  // rayshade() with the alternate material
        light = false;
    } else if (k >= 0) {
        Contribute(k, r, point, normal, t,
                   CONTRIBUTIONS != 0 ? Colour(m, r, point, normal, t) : vec3(1));
    }
    if (m.kind == kMatAntimatter) {
        PassAntimatter(r, m, point);
        return;
    }
    if (FIRST_HIT != 0 && (r.crtype & ~(kPrimary | kTrans)) == 0 && !light && m.kind != kMatGlow) {
        if ((int(m.params.w) & kSurfaceTransparent) != 0) {
            Ray c;
            if (Spawn(r, kTrans, vec3(1), c)) {
                c.org = point;
                Item it; it.r = c; it.kind = kItemTrace; Push(it);
            }
            return;
        }
        // raytirrad(): a Lambertian surface of reflectance pi.
        m.kind = kMatDiffuse;
        m.color = vec4(kPi, kPi, kPi, 0);
        m.params = vec4(0);
        m.alpha2 = 0;
        m.pattern = -1;
    }
    ShadeMaterial(r, object, m, point, normal, rod, t);
}

uint pushed0 = 0u;  // first-level hemispheres pushed by this task

#ifdef ASUB
// -asub (the CPU integrator's RayState::diffuse_scale): a first-level sub-sample starts the
// diffuse paths of its cell (scale ASUB^2) or none (0); false for none.
bool ScaleForDiffuse(inout Ray r) {
    if (r.dscale == 0.0) return false;
    r.coef *= r.dscale;
    r.dscale = 1.0;
    return true;
}
#endif

void PushHemisphere(Ray r, vec3 colour, vec3 point, vec3 normal) {
    if (r.adepth >= AB || AD <= 0) return;
    if (Bright(colour) <= kTiny) return;
#ifdef ASUB
    if (!ScaleForDiffuse(r)) return;
#endif
    float wt = r.weight;
    float d = 0.8 * Max3(colour) * r.weight / float(AD * LW);
    if (wt > d) wt = d;
    int n = int(sqrt(float(AD) * wt) + 0.5);
    if (n < 1) n = 1;
    Item it;
    it.r = r;
    it.kind = kItemAmbient;
    it.point = point;
    it.normal = normal;
    it.colour = colour / float(n * n);
    it.n = n;
    it.next = 0;
    it.end = n * n;
#ifdef ASUB
    if (r.adepth == 0) it.end *= ASUB * ASUB;  // steps: the cells' sub-samples
#endif
    // The grid's turn: at the first level from numbers keyed by the hemisphere, so that every
    // slice of a sensor's hemisphere turns it the same way.
    uint saved = rng;
    if (r.adepth == 0) rng = Key(cell_key, ++pushed0, 0x2545f491u, 7u);
    float t0 = Rand(), t1 = Rand(), t2 = Rand(), t3 = Rand();
    if (r.adepth == 0) rng = saved;
    it.incident = RandomTangent(normal, t0, t1, t2, t3);
    Push(it);
}

void PushDirect(Ray r, vec3 colour, float rdiff, float tdiff, float trans, bool fresnel,
                vec3 point, vec3 normal, vec3 spec, float alpha2) {
    if (tasks.ndirect == 0) return;  // glow sources are found only by escaping rays
    bool rough = alpha2 > 0 && Max3(spec) > 0;
    if ((Max3(colour) <= 0 || (rdiff <= kTiny && tdiff <= kTiny)) && !rough) return;
#ifdef ASUB
    if (!ScaleForDiffuse(r)) return;
#endif
    Item it;
    it.r = r;
    it.kind = kItemDirect;
    it.point = point;
    it.normal = normal;
    it.colour = colour;
    it.rdiff = rdiff;
    it.tdiff = tdiff;
    it.trans = trans;
    it.fresnel = fresnel ? 1 : 0;
    it.spec = spec;
    it.alpha2 = rough ? alpha2 : 0;
    it.incident = r.dir;
    it.next = 0;
    it.end = NSOURCES;
    it.part = 0;
    it.turn = Pcg(rng ^ 0x68e31da4u);
    Push(it);
}

void PushChild(Ray r, int type, vec3 coef, vec3 org, vec3 dir) {
    Ray c;
    if (!Spawn(r, type, coef, c)) return;
    c.org = org;
    c.dir = dir;
    Item it;
    it.r = c;
    it.kind = kItemTrace;
    Push(it);
}

// gaussamp() for reflection: SPECULAR rays about the mirror direction, their half vectors drawn
// from the Gaussian of roughness^2 alpha2; one ray (up to 10 tries to leave above) or, with -ss
// above 1.5, -ss x weight rays sharing the coefficient (the CPU's GaussianReflection()).
void PushGaussianReflection(Ray r, vec3 scolor, float alpha2, vec3 point, vec3 normal) {
    Ray c;
    if (!Spawn(r, kSpecular, scolor, c)) return;
    int target = 1;
    if (SS > 1.5) {
        target = int(SS * r.weight + .5);
        if (c.weight <= LW * float(target)) target = int(c.weight / LW);
        if (target > 1) {
            c.coef /= float(target);
            c.weight /= float(target);
        } else {
            target = 1;
        }
    }
    vec3 u, v;
    Tangents(normal, u, v);
    int taken = 0;
    [[dont_unroll]] for (int trial = 0; taken < target && trial < 10 * target; ++trial) {
        float phi = 2. * kPi * Rand();
        float rv1 = Rand();
        if (SS >= 0 && SS < 1) rv1 = 1. - SS * rv1;
        float d = rv1 <= kTiny ? 1. : sqrt(alpha2 * -log(rv1));
        vec3 h = normal + d * (cos(phi) * u + sin(phi) * v);
        vec3 dir = r.dir + (-2. * dot(h, r.dir) / (1. + d * d)) * h;
        if (dot(dir, normal) <= kTiny) continue;
        c.org = point;
        c.dir = normalize(dir);
        Item it;
        it.r = c;
        it.kind = kItemTrace;
        Push(it);
        ++taken;
    }
}

#ifdef DAYFLUX_BSDF
// ---- the BSDF material with Klems data (raytrace/klems.h and m_bsdf() in contrib.cpp; the
// data as PackKlems lays it out)
layout(std430, set = 0, binding = kBindingKlems) readonly buffer Klems { float klems[]; };
int KI(int at) { return int(klems[at]); }

int BasisIndex(int q, int slot, int rings, vec3 w) {
    if (w.z < 0 || w.z > 1.00001) return -1;
    int cosat = KI(q + slot), nphiat = KI(q + slot + 1), firstat = KI(q + slot + 2);
    if (w.z < klems[cosat + rings]) return -1;
    int ring = 0;
    while (ring + 1 < rings && w.z <= klems[cosat + ring + 1]) ++ring;
    float azi = degrees(atan(w.y, w.x));
    if (azi < 0) azi += 360.0;
    int nphi = KI(nphiat + ring);
    int ndx = int(azi / 360.0 * float(nphi) + 0.5);
    if (ndx >= nphi) ndx = 0;
    return KI(firstat + ring) + ndx;
}
vec3 ToFrontOut(bool incident, bool front, vec3 v) {
    return vec3(incident ? -v.x : v.x, incident ? -v.y : v.y, front ? v.z : -v.z);
}
// The patch of direction v in part q's incident (or outgoing) basis. (Code size matters here:
// the compiler inlines every call, so the functions below call this from as few places as
// they can.)
int PartIndex(int q, vec3 v, bool incident) {
    return BasisIndex(q, incident ? 7 : 11, KI(q + (incident ? 5 : 6)),
                      ToFrontOut(incident, klems[q + (incident ? 0 : 1)] > 0.5, v));
}
float PartOhm(int q, int i, bool incident) {
    return i < 0 ? -1.0 : klems[KI(q + (incident ? 10 : 14)) + i];
}
float KValue(int q, int o, int i) { return klems[KI(q + 15) + o * KI(q + 3) + i]; }
int PartR(int b, bool front) { return KI(b + (front ? 17 : 18)); }
int PartT(int b, bool front) {
    int own = KI(b + (front ? 19 : 20)), other = KI(b + (front ? 20 : 19));
    return own >= 0 ? own : other;
}

float KlemsEval(int b, vec3 inv, vec3 outv) {
    bool fi = inv.z > 0, fo = outv.z > 0;
    float value = klems[b + (fi == fo ? (fi ? 4 : 5) : (fi ? 6 : 7))] / kPi;
    int q = fi == fo ? PartR(b, fi) : PartT(b, fi);
    if (q < 0) return value;
    int idx[2];
    [[dont_unroll]] for (int k = 0; k < 4; ++k) {  // in, out; then, by reciprocity, the two swapped
        if (k == 2 && (idx[0] >= 0 || idx[1] >= 0)) break;
        idx[k & 1] = PartIndex(q, (k == 0 || k == 3) ? inv : outv, (k & 1) == 0);
    }
    int i = idx[0], o = idx[1];
    return i < 0 || o < 0 ? value : value + KValue(q, o, i);
}

// The row of part q's cumulative distribution for incident direction inv (by reciprocity the
// outgoing one where inv is not incident there); its length; false if none.
bool CdfRow(int q, vec3 inv, out int row, out int len, out bool reverse) {
    int nin = KI(q + 3), nout = KI(q + 4);
    row = -1;
    len = 0;
    reverse = false;
    [[dont_unroll]] for (int k = 0; k < 2 && row < 0; ++k) {
        int i = PartIndex(q, inv, k == 0);
        if (i < 0) continue;
        reverse = k == 1;
        len = reverse ? nin : nout;
        row = KI(q + (reverse ? 17 : 16)) + i * (len + 1);
    }
    return row >= 0;
}

float SpecularHemi(int b, vec3 inv, bool xmit) {
    bool front = inv.z > 0;
    int q = xmit ? PartT(b, front) : PartR(b, front);
    int row, len;
    bool reverse;
    if (q < 0 || !CdfRow(q, inv, row, len, reverse)) return 0;
    return klems[row + len];
}

// SDsizeBSDF over parts: psa.x the smallest patch met, psa.y (minmax) the largest.
void QueryProjSA(int q, vec3 v1, vec3 v2, bool same, bool minmax, inout vec2 psa) {
    float p[2];
    [[dont_unroll]] for (int k = 0; k < 4; ++k) {
        if (k == 2 && (same || p[0] > 0 || p[1] > 0)) break;
        bool incident = k == 1 || k == 2;
        vec3 v = (k == 0 || k == 2) ? v1 : v2;
        p[k & 1] = PartOhm(q, PartIndex(q, v, incident), incident);
    }
    if (minmax) psa.y = max(psa.y, max(p[0], p[1]));
    [[dont_unroll]] for (int k = 0; k < 2; ++k)
        if (p[k] > 0 && p[k] < psa.x) psa.x = p[k];
}

vec2 SizeMinMax(int b, vec3 v) {
    bool front = v.z > 0;
    vec2 psa = vec2(10, 0);
    bool any = false;
    [[dont_unroll]] for (int k = 0; k < 2; ++k) {
        int q = k == 0 ? PartR(b, front) : PartT(b, front);
        if (q < 0) continue;
        QueryProjSA(q, v, v, true, true, psa);
        any = true;
    }
    if (!any) psa = vec2(kPi);
    if (psa.x > psa.y) psa.x = psa.y;
    return psa;
}

float SizeMin(int b, vec3 v1, vec3 v2) {
    bool front = v1.z > 0;
    int q = (v1.z > 0) != (v2.z > 0) ? PartT(b, front) : PartR(b, front);
    if (q < 0) return kPi;
    vec2 psa = vec2(10, 0);
    QueryProjSA(q, v1, v2, false, false, psa);
    return psa.x;
}

// SDsampComponent: the hemispherical total for inv, and outv drawn from the distribution.
float KlemsSample(int q, vec3 inv, float rnd, float u, float v, out vec3 outv) {
    int row, len;
    bool reverse;
    outv = vec3(0);
    if (!CdfRow(q, inv, row, len, reverse)) return 0;
    float total = klems[row + len];
    if (total <= 1e-6) return 0;
    float target = clamp(rnd, 0.0, 1.0) * total;
    int lo = 0, hi = len - 1;  // the first patch whose cumulative end exceeds target
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (klems[row + mid + 1] > target) hi = mid; else lo = mid + 1;
    }
    // The patch is in the outgoing basis, or by reciprocity the incident one.
    int slot = reverse ? 7 : 11, rings = KI(q + (reverse ? 5 : 6));
    int firstat = KI(q + slot + 2);
    int ring = 0;
    while (ring + 1 < rings && lo >= KI(firstat + ring + 1)) ++ring;
    int index = lo - KI(firstat + ring);
    float c0 = klems[KI(q + slot) + ring], c1 = klems[KI(q + slot) + ring + 1];
    float cz = sqrt((1. - u) * c0 * c0 + u * c1 * c1);
    float azi = 2. * kPi * (float(index) + v - .5) / float(KI(KI(q + slot + 1) + ring));
    float sz = sqrt(max(0., 1. - cz * cz));
    outv = ToFrontOut(reverse, klems[q + (reverse ? 0 : 1)] > 0.5,
                      vec3(cos(azi) * sz, sin(azi) * sz, cz));
    return total;
}

// m_bsdf()'s frame: z the front normal, x = up x z.
vec3 kx, ky, kz, kview;
vec2 ksr;  // sqrt of the smallest and largest projected solid angles about the view
vec3 ToLocal(vec3 w) { return normalize(vec3(dot(kx, w), dot(ky, w), dot(kz, w))); }
vec3 ToWorld(vec3 l) { return normalize(kx * l.x + ky * l.y + kz * l.z); }
bool KlemsFrame(int b, vec3 front_normal, vec3 raydir) {
    vec3 up = vec3(klems[b + 1], klems[b + 2], klems[b + 3]);
    kz = normalize(front_normal);
    vec3 x = cross(up, kz);
    if (dot(x, x) == 0) return false;
    kx = normalize(x);
    ky = cross(kz, kx);
    kview = ToLocal(-raydir);
    return true;
}
vec3 KJitter(float size, float u, float v) {
    if (SS < 1.) size *= SS;
    if (size <= 1e-6) return kview;
    return normalize(kview + vec3(size * (.5 - u), size * (.5 - v), 0));
}

// direct_specular_OK(): the non-diffuse BSDF toward a source, or -1 when none is to be added.
float DirectSpecular(int b, vec3 source_dir, float weight) {
    vec3 vsrc = ToLocal(source_dir);
    bool sf = vsrc.z > 0, vf = kview.z > 0;
    float lamb;
    if (sf == vf) {
        if (PartR(b, vf) < 0) return -1;
        lamb = klems[b + (vf ? 4 : 5)];
    } else {
        if (KI(b + 19) < 0 && KI(b + 20) < 0) return -1;
        lamb = klems[b + (vf ? 6 : 7)];
    }
    float diffuse = lamb > 1e-6 ? lamb / kPi : 0.;
    float tomega = 0, tsr = 0, sum = 0;
    int nsamp = 1, count = 0;
    [[dont_unroll]] for (int i = -1; i < nsamp; ++i) {  // i = -1: the view's own size (one SizeMin call)
        vec3 vjit = kview;
        if (i >= 0) {
            float u = Rand(), v = Rand();
            vjit = KJitter(tsr, u, v);
        }
        float size = SizeMin(b, vjit, vsrc);
        if (i < 0) {
            tomega = size;
            tsr = sqrt(tomega);
            if (tsr > 0) nsamp = max(1, int(4. * SS * weight + .5));
            continue;
        }
        if (size < .12 * tomega) continue;  // a finer patch: not safe to include
        float f = KlemsEval(b, vjit, vsrc);
        if (f - diffuse <= 1e-6) continue;
        sum += f;
        ++count;
    }
    if (count == 0) return -1;
    return max(0., sum / float(count) - diffuse);
}

void ShadeBsdf(Ray r, GpuSurface m, vec3 point, vec3 normal, float t) {
    int b = m.fore;
    bool front = hit_front;
    vec3 front_normal = front ? normal : -normal;
    float thick = klems[b];
    if (abs(thick) <= kTiny) thick = 0;
    if (thick != 0 && ((r.crtype & kShadow) != 0 || (r.crtype & (kSpecular | kAmbient)) == 0 ||
                       (thick > 0) != front)) {
        PushChild(r, kTrans, vec3(1), point, r.dir);  // hide the proxy
        return;
    }
    if ((r.crtype & kShadow) != 0) return;
    vec3 pcol = Colour(m, r, point, front_normal, t);  // colour 1: the pattern alone
    int e = front ? 8 : 11;
    vec3 rdiff = (klems[b + (front ? 4 : 5)] +
                  vec3(klems[b + e], klems[b + e + 1], klems[b + e + 2])) * pcol;
    vec3 tdiff = (klems[b + (front ? 6 : 7)] + vec3(klems[b + 14], klems[b + 15], klems[b + 16])) *
                 pcol;
    if (!KlemsFrame(b, front_normal, r.dir)) return;
    ksr = sqrt(SizeMinMax(b, kview));
    vec3 behind = point - thick * front_normal;
    // sample_sdf() for reflection, then transmission: a specular ray from the part serving the
    // ray's side, or (below -st) the total left to the ambient hemisphere on that side.
    [[dont_unroll]] for (int xmit = 0; xmit < 2; ++xmit) {
        vec3 unsampled = vec3(0);
        int q = xmit == 1 ? PartT(b, kview.z > 0) : PartR(b, kview.z > 0);
        if (q >= 0) {
            float hemi = 0;
            if (klems[q + 2] > kTiny) {
                float u = Rand(), v = Rand();
                hemi = max(0., SpecularHemi(b, KJitter(ksr.y, u, v), xmit == 1));
            }
            if (hemi <= ST + kTiny) {
                if (hemi > kTiny) unsampled = hemi * (xmit == 1 ? pcol : vec3(1));
            } else {
                // -ss above 1.5: -ss x weight samples, stratified in xrand, sharing the value
                int target = SS > 1.5 ? max(1, int(SS * r.weight + .5)) : 1;
                [[dont_unroll]] for (int n = 0; n < target; ++n) {
                    float xrand = Rand();
                    if (target == 1) {
                        if (SS < 1.) xrand = .5 + SS * (xrand - .5);
                    } else {
                        xrand = (float(n) + xrand) / float(target);
                    }
                    float u = Rand(), v = Rand();
                    vec3 vsmp = KJitter(ksr.x, u, v), outv;
                    float value = KlemsSample(q, vsmp, xrand, Rand(), Rand(), outv);
                    if (value <= kTiny) break;
                    if (target > 1) value /= float(target);
                    Ray c;
                    if (!Spawn(r, kSpecular, value * (xmit == 1 ? pcol : vec3(1)), c)) {
                        if (n == 0 && target > 1) {  // RADIANCE lowers its target, starts again
                            int before = target;
                            target = int(float(target) * c.weight / LW);
                            if (target == before) break;
                            n = -1;
                        }
                        continue;
                    }
                    c.org = xmit == 1 ? behind : point;
                    c.dir = ToWorld(outv);
                    Item it;
                    it.r = c;
                    it.kind = kItemTrace;
                    Push(it);
                }
            }
        }
        // The diffuse part and what was not sampled, as an ambient hemisphere on that side
        // (m_bsdf() moves a proxy's origin along the normal as flipped for a front hit only).
        vec3 origin = xmit == 0 ? point : point + thick * (front ? -front_normal : front_normal);
        PushHemisphere(r, (xmit == 0 ? rdiff : tdiff) + unsampled, origin,
                       xmit == 0 ? normal : -normal);
    }
    if (tasks.ndirect == 0) return;
    // direct(): dir_bsdf(), or dir_brdf() and dir_btdf() apart for a proxy.
    Item it;
    it.r = r;
    it.kind = kItemDirectBsdf;
    it.normal = normal;
    it.colour = rdiff;
    it.spec = tdiff;
    it.incident = pcol;
    it.n = b;
    it.next = 0;
    it.end = NSOURCES;
    it.part = 0;
    it.turn = Pcg(rng ^ 0x68e31da4u);
    bool reflect_only = Bright(tdiff) <= kTiny && KI(b + 19) < 0 && KI(b + 20) < 0;
    it.point = point;
    it.fresnel = (front ? 1 : 0) | 2 | (reflect_only || thick != 0 ? 0 : 4);
    Push(it);
    if (thick != 0 && !reflect_only) {
        it.point = behind;
        it.fresnel = (front ? 1 : 0) | 4;
        Push(it);
    }
}
#endif

void ShadeBasic(Ray r, GpuSurface m, vec3 point, vec3 normal, float rod, float t);

// What a material does with a ray (after Shade's rules for lights, antimatter and -i). A mirror
// with a substitute material: m_mirror() gives it the rays other than those the direct
// calculation sends through the mirror toward an image, and ambient and specular rays meeting
// its front (the light those would find comes through the images). A mixfunc, raymixture():
// each side shades its share of the ray (a void side lets its share through). GLSL has no
// recursion, so the sides of mixfuncs of mixfuncs wait on a small stack (the host refuses trees
// deeper than it holds). One call of ShadeBasic, so that the compiler inlines it once.
void ShadeMaterial(Ray r, int object, GpuSurface m, vec3 point, vec3 normal, float rod, float t) {
    bool substituted = !(r.aimed >= 0 && sources[r.aimed].relay >= 0 &&
                         sources[r.aimed].object == object) &&
                       !((r.crtype & (kAmbient | kSpecular)) != 0 && hit_front);
    int waiting[kMixStack];
    float waiting_share[kMixStack];
    int nwaiting = 0;
    float share = 1;
    for (;;) {
        Ray part = r;
        part.weight *= share;
        part.coef *= share;
        if (m.kind == kMatMirror && (int(m.params.w) & kSurfaceMirrorAlternate) != 0 &&
            substituted) {
            if (m.fore < 0) {
                PushChild(part, kTrans, vec3(1), point, part.dir);
            } else {
                m = surfaces[m.fore];
                if (m.kind != kMatAntimatter) continue;  // shaded as the mirror would have been
                PassAntimatter(part, m, point);
            }
        } else if (m.kind == kMatMix) {
            SetRayVariables(r, point, normal, t);
            float c = clamp(float(PatternRGB(m.pattern).x), 0.0, 1.0);
            for (int side = 1; side >= 0; --side) {  // the foreground is shaded first
                float fraction = side == 0 ? c : 1 - c;
                if (fraction <= kTiny) continue;
                int s = side == 0 ? m.fore : m.back;
                if (s < 0) {
                    Ray through = part;
                    through.weight *= fraction;
                    through.coef *= fraction;
                    PushChild(through, kTrans, vec3(1), point, through.dir);
                    continue;
                }
                waiting[nwaiting] = s;
                waiting_share[nwaiting] = share * fraction;
                ++nwaiting;
            }
        } else {
            ShadeBasic(part, m, point, normal, rod, t);
        }
        if (nwaiting == 0) return;
        --nwaiting;
        m = surfaces[waiting[nwaiting]];
        share = waiting_share[nwaiting];
    }
}

#ifdef DAYFLUX_DIELECTRIC
// m_dielectric() as the CPU integrator has it: Fresnel reflection and refraction, the refracted
// ray carrying the solid angle ratio; the medium's extinction only weighs the rays it spawns
// (raycontrib() leaves it out of contributions). cos1 = rod > 0, normal faces the ray.
void ShadeDielectric(Ray r, GpuSurface m, vec3 point, vec3 normal, float cos1, float t) {
    GpuSurface unit = m;
    unit.color.rgb = vec3(1);
    vec3 pcol = Colour(unit, r, point, normal, t), ext;
    for (int k = 0; k < 3; ++k) {  // RADIANCE's mylog()
        float x = m.color[k] * pcol[k];
        ext[k] = x < 1e-38 ? 100.0 : x >= 1.0 ? 0.0 : -log(x);
    }
    float nratio = m.color.w;
    Ray inc = r;  // the incident ray: inside, it travelled in the medium
    inc.t = t;
    vec3 ctrans = vec3(0);
    if (!hit_front) {
        inc.cext = ext;
    } else {
        nratio = 1.0 / nratio;
        ctrans = ext;
    }
    float refl = 1.0;
    float d2 = 1.0 - nratio * nratio * (1.0 - cos1 * cos1);
    if (d2 >= kTiny) {  // else total reflection
        float cos2 = sqrt(d2);
        float a = (cos1 - nratio * cos2) / (cos1 + nratio * cos2);
        float b = (1.0 / cos1 - nratio / cos2) / (1.0 / cos1 + nratio / cos2);
        refl = .5 * (a * a + b * b);
        Ray c;
        if (Spawn(inc, kRefracted, vec3((1.0 - refl) * nratio * nratio), c)) {
            c.org = point;
            c.dir = normalize(nratio * r.dir + (nratio * cos1 - cos2) * normal);
            c.cext = ctrans;
            Item it;
            it.r = c;
            it.kind = kItemTrace;
            Push(it);
        }
    }
    if ((r.crtype & kShadow) != 0) return;
    PushChild(inc, kReflected, vec3(refl), point, normalize(r.dir + 2.0 * cos1 * normal));
}
#endif

void ShadeBasic(Ray r, GpuSurface m, vec3 point, vec3 normal, float rod, float t) {
    if (m.kind == kMatBlack || m.kind == kMatGlow || m.kind == kMatLight || m.kind == kMatIllum ||
        m.kind == kMatAntimatter)  // (a mixfunc's side)
        return;
#ifdef DAYFLUX_BSDF
    if (m.kind == kMatBsdf) {
        ShadeBsdf(r, m, point, normal, t);
        return;
    }
#endif
#ifdef DAYFLUX_DIELECTRIC
    if (m.kind == kMatDielectric) {
        ShadeDielectric(r, m, point, normal, rod, t);
        return;
    }
#endif
    vec3 c = Colour(m, r, point, normal, t);
    if (m.kind == kMatMirror) {  // its back is black
        if (!hit_front) return;
        vec3 reflected = normalize(r.dir + 2 * rod * normal);
#ifdef DAYFLUX_MIRROR_IMAGES
        // A shadow ray through the mirror toward the source it images: on to the next source,
        // whatever the limits (rayorigin()'s verdict is ignored there). Shade() set r.from.
        if (r.aimed >= 0 && sources[r.aimed].relay >= 0 && sources[r.aimed].object == r.from) {
            Item it;
            it.kind = kItemTrace;
            it.r = r;
            it.r.depth = r.depth + 1;
            it.r.rlvl = r.rlvl + 1;
            it.r.crtype = r.crtype | kReflected;
            it.r.aimed = sources[r.aimed].next;
            it.r.coef = r.coef * c;
            it.r.org = point;
            it.r.dir = reflected;
#ifdef DAYFLUX_DIELECTRIC
            it.r.t = 0;
#endif
            Push(it);
            return;
        }
#endif
        if ((r.crtype & kShadow) != 0) return;
        PushChild(r, kReflected, c, point, reflected);
        return;
    }
    if (m.kind == kMatGlass) {
        vec3 mc = max(c, vec3(1e-15));
        bool hastrans = Max3(c) > 1e-15;
        float n = m.color.w, pdot = rod;
        float cos2 = sqrt((1.0 - 1.0 / (n * n)) + pdot * pdot / (n * n));
        if (hastrans) mc = pow(mc, vec3(1.0 / cos2));
        float r1e = (pdot - n * cos2) / (pdot + n * cos2);
        r1e *= r1e;
        float r1m = (1.0 / pdot - n / cos2) / (1.0 / pdot + n / cos2);
        r1m *= r1m;
        if (hastrans) {
            vec3 tr = .5 * (1.0 - r1e) * (1.0 - r1e) * mc / (1.0 - r1e * r1e * mc * mc) +
                      .5 * (1.0 - r1m) * (1.0 - r1m) * mc / (1.0 - r1m * r1m * mc * mc);
            PushChild(r, kTrans, tr, point, r.dir);
        }
        if ((r.crtype & kShadow) != 0) return;
        vec3 dd = mc * mc;
        vec3 refl = .5 * r1e * (1.0 + (1.0 - 2.0 * r1e) * dd) / (1.0 - r1e * r1e * dd) +
                    .5 * r1m * (1.0 + (1.0 - 2.0 * r1m) * dd) / (1.0 - r1m * r1m * dd);
        PushChild(r, kReflected, refl, point, normalize(r.dir + 2 * pdot * normal));
        return;
    }
    // plastic, metal, trans (m_normal()): pure specular reflection with RADIANCE's Fresnel
    // estimate, or rough (Gaussian) reflection sampled or, below -st, folded into the diffuse
    // part; pure specular and diffuse transmission.
    float spec = m.params.x;
    bool metal = (int(m.params.w) & kSurfaceMetal) != 0;
    bool pure = m.alpha2 <= kTiny;
    float rspec = spec, fest = 0;
    float pdot = max(rod, .001);
    if (pure && rspec >= kFresnelThreshold) {
        fest = FresnelEstimate(pdot);
        rspec += fest * (1. - rspec);
    }
    float trans = m.params.y * (1. - rspec), tspec = trans * m.params.z;
    float tdiff = trans - tspec;
    if (tspec > kTiny) PushChild(r, kTrans, c * tspec, point, r.dir);
    if ((r.crtype & kShadow) != 0) return;
    vec3 sc = vec3(0);
    bool rough_below_threshold = false;
    if (rspec > kTiny) {
        sc = vec3(rspec);
        if (metal) sc = fest > kTiny ? fest + c * spec * (1. - fest) : c * rspec;
        if (pure)
            PushChild(r, kReflected, sc, point, normalize(r.dir + 2 * pdot * normal));
        else if (ST >= rspec - kTiny)
            rough_below_threshold = true;
        else
            PushGaussianReflection(r, sc, m.alpha2, point, normal);
    }
    float rdiff = 1.0 - trans - rspec;
    if (pure && rdiff <= kTiny && tdiff <= kTiny) return;
    PushDirect(r, c, rdiff, tdiff, trans, pure && spec >= kFresnelThreshold, point, normal, sc,
               pure || rspec <= kTiny ? 0.0 : m.alpha2);
    if (tdiff > kTiny) PushHemisphere(r, c * tdiff, point, -normal);
    if (rdiff > kTiny) PushHemisphere(r, c * rdiff + (rough_below_threshold ? sc : vec3(0)), point, normal);
}

// Where a ray ends: a triangle, or a distant source for rays that hit nothing (sourcehit()).
struct Hit {
    int object, tracked;
    GpuSurface m;
    vec3 point, normal;
    float t;
};

bool Escape(Ray r, out Hit h) {
    int glow = -1, chosen = -1;
    int first = r.aimed >= 0 ? r.aimed : 0, last = r.aimed >= 0 ? r.aimed + 1 : NSOURCES;
    for (int i = first; i < last; ++i) {
        if (int(sources[i].u.w) != kSourceDistant || sources[i].relay >= 0) continue;
        float c = dot(sources[i].dir.xyz, r.dir);
        if (2. * kPi * (1. - c) > sources[i].dir.w) continue;
        if (sources[i].colour.w > 0.5 && r.aimed < 0) {
            if (glow < 0) glow = i;
            continue;
        }
        chosen = i;
        break;
    }
    if (chosen < 0) chosen = glow;
    if (chosen < 0) return false;
    GpuSource s = sources[chosen];
    h.object = s.object;
    h.tracked = s.tracked;
    h.m.color = vec4(s.colour.rgb, 0);
    h.m.params = vec4(0);
    h.m.alpha2 = 0;
    h.m.pattern = s.pattern;
    h.m.kind = s.kind;
    h.m.tracked = s.tracked;
    h.m.fore = -1;
    h.m.back = -1;
    h.m.clip = 0u;
    h.point = r.dir * 1e30;
    h.normal = -r.dir;
    h.t = 1e30;
    return true;
}

bool FindHit(Ray r, out Hit h) {
    float t;
    int prim, shape;
    if (!Closest(r.org, r.dir, r.from, t, prim, shape)) return Escape(r, h);
    if (shape >= 0) {
        GpuShape s = shapes[shape];
        h.point = r.org + t * r.dir;
        h.normal = ShapeNormal(s, h.point);
        h.m = surfaces[s.surface];
        h.object = s.object;
        h.tracked = h.m.tracked;
        h.t = t;
        return true;
    }
    GpuTriangle tri = triangles[prim];
    // On the triangle's plane, then into the triangle (see ClosestPointOnTriangle).
    vec3 a = Vertex(indices[3 * prim]), b = Vertex(indices[3 * prim + 1]),
         c = Vertex(indices[3 * prim + 2]);
    float dn = dot(r.dir, tri.normal.xyz);
    if (dn != 0) {
        float tp = dot(a - r.org, tri.normal.xyz) / dn;
        if (tp > 0) t = tp;
    }
    h.point = ClosestPointOnTriangle(r.org + t * r.dir, a, b, c);
    h.m = surfaces[tri.surface];
    h.object = tri.object;
    h.tracked = h.m.tracked;
    h.normal = tri.normal.xyz;
    h.t = t;
    return true;
}

// One shadow ray toward source i (direct() with dirnorm() and rcontrib's -dt 0).
// A direction to distant source s, jittered over it by -dj (nextssamp()).
vec3 SourceDirection(GpuSource s) {
    vec3 dir = s.dir.xyz;
    if (DJ > kTiny) {
        float pu = DJ * (1. - 2. * Rand()), pv = DJ * (1. - 2. * Rand());
        if (DJ > 0.7) {
            float c = 1.12837917;
            float tu = c * sqrt(1. - .5 * pv * pv), tv = c * sqrt(1. - .5 * pu * pu);
            pu *= tu;
            pv *= tv;
        }
        dir = normalize(dir + pu * s.u.xyz + pv * s.v.xyz);
    }
    return dir;
}

// The shadow ray toward source i carrying coef, when it could bring anything.
void ShadowRay(Item it, int i, GpuSource s, vec3 dir, vec3 coef) {
    if (Max3(coef) <= 0 || Bright(coef * s.colour.rgb) <= 0) return;
    Ray c = it.r;
    c.depth = it.r.depth + 1;
    c.rlvl = it.r.rlvl + 1;
    c.crtype = it.r.crtype | kShadow;
    c.aimed = i;
    c.coef = it.r.coef * coef;
    c.org = it.point;
    c.dir = dir;
    Item sh;
    sh.r = c;
    sh.kind = kItemTrace;
    Push(sh);
}

#ifdef DAYFLUX_LOCAL_SOURCES  // only scenes with local light sources compile this
// nextssamp() for local source s seen from origin (the CPU integrator's LocalSamples()): a
// flat source split into parts no larger than -ds times their distance (as the ray's weight
// allows), a cylinder split along its axis, a sphere whole. Returns the number of parts; with
// want >= 0, dir and omega (0: none) of a sample jittered by -dj in part `want`. The squares of
// turned sources are turned by numbers keyed by `turn`, the same for every part.
const int kMaxParts = 64;  // RADIANCE's MAXSPART
struct PartNode {
    ivec4 part;  // centre (xy) and size (zw) in 64ths
    vec3 cent, u, w;
    float du2, dv2;
    int mp;
};
int LocalSample(GpuSource s, int i, vec3 origin, float weight, uint turn, int want, out vec3 dir,
                out float omega) {
    dir = vec3(0);
    omega = 0;
    int shape = int(s.u.w), flags = int(s.v.w);
    bool isflat = shape == kSourceFlat;
    vec3 loc = s.dir.xyz, axis = s.norm.xyz, ss0 = s.u.xyz, ss1 = s.v.xyz, ss2 = s.w.xyz;
    if ((flags & kSourceTurned) != 0) {
        uint saved = rng;
        rng = Key(turn, uint(i), 3u, 11u);
        float r0 = Rand(), r1 = Rand(), r2 = Rand(), r3 = Rand();
        rng = saved;
        if (shape == kSourceCylinder) {  // cylsetsrc(): SW across the axis, SV = SW x axis
            ss2 = RandomTangent(axis, r0, r1, r2, r3) * (.8559 * s.w.w);
            ss1 = cross(ss2, axis);
        } else {  // setflatss(): a square of the source's area
            float mult = .5 * sqrt(s.dir.w);
            ss0 = RandomTangent(axis, r0, r1, r2, r3);
            ss1 = cross(axis, ss0) * mult;
            ss0 *= mult;
        }
    }
    vec3 v = origin - loc;
    int nparts = 0;
    ivec4 chosen = ivec4(0, 0, kMaxParts, kMaxParts);
    PartNode nodes[8];
    int sp = 0;
    if (isflat) {
        if (dot(v, axis) <= 0) return 0;  // behind
        if (DS <= kTiny) {
            nparts = 1;
        } else {
            float lim = 2. * weight / DS;
            lim *= lim;
            nodes[0] = PartNode(ivec4(0, 0, kMaxParts, kMaxParts), loc, ss0, ss1,
                                lim * dot(ss0, ss0), lim * dot(ss1, ss1), kMaxParts);
            sp = 1;
            while (sp > 0) {  // flt_partit(), depth first, the lower halfv first
                PartNode e = nodes[--sp];
                float d2 = dot(origin - e.cent, origin - e.cent);
                if (e.mp < 2 || (d2 >= e.du2 && d2 >= e.dv2)) {
                    if (nparts == want) chosen = e.part;
                    ++nparts;
                    continue;
                }
                int ax = e.du2 > e.dv2 ? 0 : 1;
                vec3 halfv = .5 * (ax == 0 ? e.u : e.w);
                PartNode c = e;
                c.mp = e.mp / 2;
                if (ax == 0) { c.u = halfv; c.du2 *= .25; } else { c.w = halfv; c.dv2 *= .25; }
                c.part[2 + ax] >>= 1;
                for (int side = 1; side >= -1; side -= 2) {
                    PartNode sub = c;
                    sub.cent = e.cent + float(side) * halfv;
                    sub.part[ax] += side * c.part[2 + ax];
                    nodes[sp++] = sub;
                }
            }
        }
    } else if (shape == kSourceCylinder) {  // cylpart()
        float rad2 = 1.365 * dot(ss1, ss1);
        float along = dot(v, ss0), safe2 = dot(ss0, ss0);
        along *= along / safe2;
        float cent2 = dot(v, v), off2 = cent2 - along;
        if (off2 <= rad2) return 0;  // inside the extended cylinder
        safe2 *= DS > kTiny ? 4. * weight * weight / (DS * DS) : 0.;
        if (DS <= kTiny || off2 <= 4. * rad2 || cent2 >= safe2) {
            nparts = 1;
        } else {
            nodes[0] = PartNode(ivec4(0, 0, kMaxParts, kMaxParts), loc, ss0, vec3(0), safe2, 0,
                                kMaxParts);
            sp = 1;
            while (sp > 0) {
                PartNode e = nodes[--sp];
                float d2 = dot(origin - e.cent, origin - e.cent);
                if (e.mp < 2 || d2 >= e.du2) {
                    if (nparts == want) chosen = e.part;
                    ++nparts;
                    continue;
                }
                vec3 halfv = .5 * e.u;
                PartNode c = e;
                c.mp = e.mp / 2;
                c.u = halfv;
                c.du2 *= .25;
                c.part.z >>= 1;
                for (int side = 1; side >= -1; side -= 2) {
                    PartNode sub = c;
                    sub.cent = e.cent + float(side) * halfv;
                    sub.part.x += side * c.part.z;
                    nodes[sp++] = sub;
                }
            }
        }
    } else {
        nparts = 1;
    }
    if (want < 0 || want >= nparts) return nparts;
    vec3 vpos = vec3(0);
    ivec3 size = ivec3(chosen.zw, kMaxParts);
    if (DJ > kTiny)
        for (int k = 0; k < (isflat ? 2 : 3); ++k)
            vpos[k] = DJ * (1. - 2. * Rand()) * float(size[k]) / float(kMaxParts);
    vpos.xy += vec2(chosen.xy) / float(kMaxParts);
    if ((flags & kSourceCircular) != 0 && (nparts > 1 || DJ > 0.7)) {  // toward the disc
        if (isflat) {
            float c = 1.12837917;
            float tu = c * sqrt(1. - .5 * vpos.y * vpos.y), tv = c * sqrt(1. - .5 * vpos.x * vpos.x);
            vpos.x *= tu;
            vpos.y *= tv;
        } else {
            float sum = dot(vpos, vpos), mx = max(vpos.x * vpos.x, max(vpos.y * vpos.y, vpos.z * vpos.z));
            vpos *= sum > kTiny * kTiny ? sqrt(mx / sum) / 0.7236 : 0.;
        }
    }
    vec3 to = loc + vpos.x * ss0 + vpos.y * ss1 + vpos.z * ss2 - origin;
    float d = length(to);
    if (d == 0) return nparts;  // at the source
    dir = to / d;
    float dom = 1.;
    if (isflat) {
        dom = -dot(axis, dir) * float(size.x * size.y) / float(kMaxParts * kMaxParts);
    } else if (shape == kSourceCylinder) {  // scylform()
        float a = dot(dir, axis);
        dom = sqrt(max(0., 1. - a * a)) * float(size.x) / float(kMaxParts);
    }
    if (dom <= 1e-4) return nparts;  // behind the source
    if (s.norm.w > 0 && s.norm.w < 2. * kPi * (1. + dot(s.spot.xyz, dir))) return nparts;
    float dist = d + (s.norm.w > 0 ? s.spot.w : 0.);  // a spot's focus distance (srcray())
    omega = dom * s.dir.w / (dist * dist);
    return nparts;
}

#endif

#ifdef DAYFLUX_MIRROR_IMAGES
// Whether the ray from org along dir meets mirror `relay` (MirrorRelay::Meets): RADIANCE's
// srcvalue() asks the relay alone before a shadow ray is traced toward an image.
bool RelayMeets(int relay, vec3 org, vec3 dir) {
    vec4 plane = relays[3 * relay], disc = relays[3 * relay + 1], outline = relays[3 * relay + 2];
    float dn = dot(dir, plane.xyz);
    if (dn == 0) return false;
    float t = (plane.w - dot(org, plane.xyz)) / dn;
    if (t <= 0) return false;
    vec3 p = org + t * dir;
    int first = int(outline.x), n = int(outline.y);
    if (n == 0) {  // a ring
        vec3 e = p - disc.xyz;
        float d2 = dot(e, e);
        return d2 >= outline.z && d2 <= disc.w;
    }
    // Crossings of a ray in the plane, projected along the normal's largest axis.
    vec3 an = abs(plane.xyz);
    int ax = an.x >= an.y && an.x >= an.z ? 0 : an.y >= an.z ? 1 : 2;
    int a = (ax + 1) % 3, b = (ax + 2) % 3;
    bool inside = false;
    [[dont_unroll]] for (int i = 0, j = n - 1; i < n; j = i++) {
        vec3 vi = relays[first + i].xyz, vj = relays[first + j].xyz;
        if ((vi[b] > p[b]) != (vj[b] > p[b]) &&
            p[a] < (vj[a] - vi[a]) * (p[b] - vi[b]) / (vj[b] - vi[b]) + vi[a])
            inside = !inside;
    }
    return inside;
}
#endif

// A sample of source i for a direct item: its direction and solid angle (0: none). An image is
// sampled only from in front of its mirror, and only through it.
bool SourceSample(Item it, int i, GpuSource s, out vec3 dir, out float omega) {
#ifdef DAYFLUX_MIRROR_IMAGES
    if (s.relay >= 0 && dot(relays[3 * s.relay].xyz, it.point) <= relays[3 * s.relay].w)
        return false;
#endif
    bool found = false;
    if (int(s.u.w) == kSourceDistant) {
        dir = SourceDirection(s);
        omega = s.dir.w;
        found = true;
    }
#ifdef DAYFLUX_LOCAL_SOURCES
    else {
        LocalSample(s, i, it.point, it.r.weight, it.turn, it.part, dir, omega);
        found = omega > 0;
    }
#endif
#ifdef DAYFLUX_MIRROR_IMAGES
    if (found && s.relay >= 0) found = RelayMeets(s.relay, it.point, dir);
#endif
    return found;
}

void DirectStep(Item it, int i) {
    GpuSource s = sources[i];
    if (s.colour.w > 0.5) return;  // glow: found only by escaping rays
    vec3 dir;
    float omega;
    if (!SourceSample(it, i, s, dir, omega)) return;
    float ldot = dot(it.normal, dir);
    if (ldot < 0 ? it.trans <= kTiny : it.trans >= 1 - kTiny) return;
    float lrdiff = it.rdiff, ltdiff = it.tdiff;
    if (it.fresnel != 0 && (lrdiff > kTiny || ltdiff > kTiny)) {
        float f = 1. - FresnelEstimate(abs(ldot));
        lrdiff *= f;
        ltdiff *= f;
    }
    float k = 0;
    if (ldot > kTiny && lrdiff > kTiny) k = ldot * omega * lrdiff / kPi;
    if (ldot < -kTiny && ltdiff > kTiny) k = -ldot * omega * ltdiff / kPi;
    vec3 coef = it.colour * k;
    if (it.alpha2 > 0 && ldot > kTiny) {
        // The Gaussian lobe toward the source, widened by the source's size.
        float a2 = it.alpha2 + omega * (0.25 / kPi);
        vec3 h = dir - it.incident;
        float d2 = dot(h, it.normal);
        d2 *= d2;
        float d3 = dot(h, h);
        float d4 = (d3 - d2) / d2;
        float g = exp(-d4 / a2) * d3 / (kPi * d2 * d2 * a2);
        if (g > kTiny) coef += it.spec * g * ldot * omega;
    }
    ShadowRay(it, i, s, dir, coef);
}

#ifdef DAYFLUX_BSDF
// dir_bsdf() (dir_brdf(), dir_btdf()): the diffuse parts and the BSDF toward the source; the
// item's fresnel holds 1 front, 2 reflection, 4 transmission.
void DirectStepBsdf(Item it, int i) {
    GpuSource s = sources[i];
    if (s.colour.w > 0.5) return;
    vec3 dir;
    float omega;
    if (!SourceSample(it, i, s, dir, omega)) return;
    float ldot = dot(it.normal, dir);
    bool reflect = (it.fresnel & 2) != 0, transmit = (it.fresnel & 4) != 0;
    if (abs(ldot) <= kTiny || (ldot > 0 && !reflect) || (ldot < 0 && !transmit)) return;
    vec3 diffuse = ldot > 0 ? it.colour : it.spec;
    vec3 coef = Bright(diffuse) > kTiny ? diffuse * abs(ldot) * omega / kPi : vec3(0);
    bool front = (it.fresnel & 1) != 0;
    if (KlemsFrame(it.n, front ? it.normal : -it.normal, it.r.dir)) {
        float spec = DirectSpecular(it.n, dir, it.r.weight);
        if (spec >= 0) coef += spec * (ldot < 0 ? it.incident : vec3(1)) * abs(ldot) * omega;
    }
    ShadowRay(it, i, s, dir, coef);
}
#endif

// Hemispheres follow RADIANCE's ambcollision(): a direction within a quarter division of an
// earlier neighbour's is drawn again in its cell. The neighbours already drawn are (i, j + 1) and
// the row before, so each hemisphere keeps two rows of directions: row i in slot i & 1. One
// hemisphere per ambient depth is active at a time (the stack finishes a hemisphere's cells
// before a sibling's), so the rows are kept per depth: up to MAXN cells a side at depth 0, 16
// below it (deeper hemispheres rarely have more than 2), for the first kDeepLevels depths.
// The first hemisphere's cells have random numbers keyed by the cell, so a task tracing some of
// its rows replays the directions of the rows before them without tracing them.
const int kDeepN = 16, kDeepLevels = 12;
vec3 rows0[2 * MAXN];
vec3 rowsd[kDeepLevels * 2 * kDeepN];

bool CollisionRule(int depth, int n) {
    return n > 1 && (depth == 0 ? n <= MAXN : depth <= kDeepLevels && n <= kDeepN);
}
vec3 RowDir(int depth, int slot, int j) {
    return depth == 0 ? rows0[slot * MAXN + j] : rowsd[((depth - 1) * 2 + slot) * kDeepN + j];
}
void SetRowDir(int depth, int slot, int j, vec3 d) {
    if (depth == 0)
        rows0[slot * MAXN + j] = d;
    else
        rowsd[((depth - 1) * 2 + slot) * kDeepN + j] = d;
}

bool CellDirection(Item it, int i, int j, float cos_thresh, bool check, out Ray child,
                   out vec3 dir) {
    Ray r = it.r;
    if (!Spawn(r, kAmbient, it.colour, child)) return false;
    child.adepth = r.adepth + 1;
    vec3 ux = it.incident, uy = cross(it.normal, ux);
    int d = r.adepth, cur = i & 1, prev = (i + 1) & 1;
    float u = Rand(), v = Rand();
    for (int tries = 0;; ++tries) {
        vec2 xy = SquareToDisk((j + v) / it.n, (i + u) / it.n);
        float z = sqrt(max(0.0, 1. - dot(xy, xy)));
        dir = normalize(xy.x * ux + xy.y * uy + z * it.normal);
        if (!check || tries == 1000) break;
        bool hit = (j + 1 < it.n && dot(RowDir(d, cur, j + 1), dir) >= cos_thresh) ||
                   (i + 1 < it.n &&
                    ((j > 0 && dot(RowDir(d, prev, j - 1), dir) >= cos_thresh) ||
                     dot(RowDir(d, prev, j), dir) >= cos_thresh ||
                     (j + 1 < it.n && dot(RowDir(d, prev, j + 1), dir) >= cos_thresh)));
        if (!hit) break;
        u = Rand();
        v = Rand();
    }
    return true;
}


uint hemispheres0 = 0u;  // first-level hemispheres started by this task (random-number keys)

#ifdef ASUB
// -asub: step k of a first-level hemisphere is sub-sample k % ASUB^2 of cell k / ASUB^2, in the
// cell's ASUB x ASUB sub-cells (as the CPU integrator's SubsampledHemisphere()); one chosen per
// cell carries its diffuse paths. No ambcollision(). Returns true if it pushed the ray.
bool SubsampleStep(Item it, int k) {
    const int per = ASUB * ASUB;
    int cell = k / per, s = k % per;
    int i = it.n - 1 - cell / it.n, j = it.n - 1 - cell % it.n;
    if (k == 0) ++hemispheres0;
    rng = Key(cell_key, uint(cell), 0x85ebca6bu, hemispheres0);  // the same for the cell's steps
    int chosen = min(per - 1, int(Rand() * float(per)));
    rng = Key(cell_key, uint(k), 0x9e3779b9u, hemispheres0);
    Item sub = it;
    sub.n = it.n * ASUB;
    Ray child;
    vec3 dir;
    if (!CellDirection(sub, i * ASUB + s / ASUB, j * ASUB + s % ASUB, 0.0, false, child, dir))
        return false;
    child.coef /= float(per);
    child.dscale = s == chosen ? float(per) : 0.0;
    child.org = it.point;
    child.dir = dir;
    Item c;
    c.r = child;
    c.kind = kItemTrace;
    Push(c);
    return true;
}
#endif

// Returns true if it pushed the cell's ray.
bool AmbientStep(inout Item it) {
    // Cells in RADIANCE's order: k = 0 is (n - 1, n - 1), then j, then i, downward.
    int k = it.next++;
#ifdef ASUB
    if (it.r.adepth == 0) return SubsampleStep(it, k);
#endif
    int i = it.n - 1 - k / it.n, j = it.n - 1 - k % it.n;
    int d = it.r.adepth;
    bool rule = CollisionRule(d, it.n);
    float spacing = (kPi / 4.) / it.n;
    float cos_thresh = 1. - .5 * spacing * spacing;
    if (rule && j == it.n - 1)  // a new row: its slot is emptied
        for (int x = 0; x < it.n; ++x) SetRowDir(d, i & 1, x, vec3(0));
    if (d == 0) {
        // The cell's own random numbers (and those of the path it starts), so that any task
        // can replay it.
        if (k == 0) ++hemispheres0;
        rng = Key(cell_key, uint(k), 0x9e3779b9u, hemispheres0);
    }
    Ray child;
    vec3 dir;
    bool ok = CellDirection(it, i, j, cos_thresh, rule, child, dir);
    if (rule) SetRowDir(d, i & 1, j, ok ? dir : vec3(0));
    if (!ok) return false;
    child.org = it.point;
    child.dir = dir;
    Item c;
    c.r = child;
    c.kind = kItemTrace;
    Push(c);
    return true;
}

void RunStack() {
    while (top > 0) {
        Item it = stack[--top];
        if (it.kind == kItemTrace) {
            if (it.r.depth > kMaxDepth) continue;  // pathological specular loops (-lr 0)
            Hit h;
            if (!FindHit(it.r, h)) continue;
            if ((it.r.clip & h.m.clip) != 0u) {
                // raycont(): antimatter hides the surface; rcontrib still sees the hit, so a
                // tracked modifier counts its coefficient (no value for -V).
                Ray r = it.r;
                if (h.tracked >= 0 && CONTRIBUTIONS == 0 &&
                    (r.aimed < 0 || h.object == sources[r.aimed].object))
                    Contribute(h.tracked, r, h.point, h.normal, h.t, vec3(1));
                r.from = h.object;
                PushChild(r, kTrans, vec3(1), h.point, r.dir);
                continue;
            }
            Shade(it.r, h.object, h.tracked, h.m, h.point, h.normal, h.t);
        } else if (it.kind == kItemAmbient) {
            if (it.next < it.end) {
                Item rest = it;
                if (AmbientStep(rest) && rest.next < rest.end && top < STACK_SIZE) {
                    // the loop goes back under the cell's ray, which runs first
                    Item child = stack[top - 1];
                    stack[top - 1] = rest;
                    stack[top++] = child;
                } else if (rest.next < rest.end) {
                    Push(rest);
                }
            }
        } else {  // kItemDirect, kItemDirectBsdf
            if (it.next < it.end) {
                // The rest of the sources (and parts) first, under this one's shadow ray.
                int i = it.next;
                int nparts = 1;
#ifdef DAYFLUX_LOCAL_SOURCES
                GpuSource s = sources[i];
                vec3 unused;
                float unused_omega;
                if (int(s.u.w) != kSourceDistant && s.colour.w < 0.5)
                    nparts = LocalSample(s, i, it.point, it.r.weight, it.turn, -1, unused,
                                         unused_omega);
#endif
                Item rest = it;
                if (it.part + 1 < nparts) {
                    rest.part = it.part + 1;
                } else {
                    rest.part = 0;
                    rest.next = i + 1;
                }
                if (rest.next < rest.end) Push(rest);
                if (nparts == 0) continue;
#ifdef DAYFLUX_BSDF
                if (it.kind == kItemDirectBsdf) {
                    DirectStepBsdf(it, i);
                    continue;
                }
#endif
                DirectStep(it, i);
            }
        }
    }
}

void Task() {
    uint local_task = gl_GlobalInvocationID.x;
    if (local_task >= uint(tasks.count)) return;
    uint task = uint(tasks.task_offset) + local_task;
    uint ray_in = task / uint(tasks.slices), slice = task % uint(tasks.slices);
    acc_base = local_task * uint(NCOLS * 3);
    if (rays[2 * ray_in + 1].w < 0) return;  // a zero direction: counts, contributes nothing
    vec3 org = rays[2 * ray_in].xyz, dir = normalize(rays[2 * ray_in + 1].xyz);
    uint ray_index = uint(tasks.first_ray) + ray_in;
    cell_key = Key(SEED, ray_index, uint(tasks.replica), 0x2545f491u);
    rng = Key(cell_key, slice, 17u, 5u);
    Ray r;
    r.org = org;
    r.dir = dir;
    r.coef = vec3(1);
    r.weight = 1;
    r.rlvl = 0;
    r.crtype = kPrimary;
    r.adepth = 0;
    r.aimed = -1;
    r.depth = 0;
    r.from = -1;
    r.clip = 0u;
#ifdef ASUB
    r.dscale = 1.0;
#endif
#ifdef DAYFLUX_DIELECTRIC
    r.cext = vec3(0);
    r.t = 0;
#endif
    if (IRRADIANCE != 0) {
        // -I: a Lambertian surface of reflectance pi at the origin, facing the ray direction.
        vec3 point = org + 1e-4 * dir;
        vec3 lamb = vec3(kPi);
        if (slice == 0u) {
            PushDirect(r, lamb, 1.0, 0.0, 0.0, false, point, dir, vec3(0), 0.0);
            RunStack();
        }
        PushHemisphere(r, lamb, point, dir);
        if (top == 0) return;
        // This slice's share of the rows; the rows before it are replayed without tracing.
        Item h = stack[--top];
        int rows = h.n, per = (rows + tasks.slices - 1) / tasks.slices;
        int row_first = int(slice) * per, row_end = min(rows, row_first + per);
        if (row_first >= row_end) return;
        int row_steps = h.n;
#ifdef ASUB
        row_steps *= ASUB * ASUB;
#endif
        for (int k = 0; k < row_first * row_steps; ++k) {
            Item replay = h;
            replay.next = k;
            AmbientStep(replay);
            top = 0;  // the cell's ray is dropped: replayed, not traced
        }
        h.next = row_first * row_steps;
        h.end = row_end * row_steps;
        Push(h);
        RunStack();
        return;
    }
    if (slice == 0u) {
        Item it;
        it.r = r;
        it.kind = kItemTrace;
        Push(it);
        RunStack();
    }
}

void main() {
    Task();
    // Items that did not fit the stack are lost: the host says how many.
    if (dropped > 0u) atomicAdd(stats_dropped, dropped);
}
