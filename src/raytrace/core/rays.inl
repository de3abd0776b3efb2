// The estimator's rays and their stack (a fragment: see language.h). RADIANCE's ray tree is
// walked with an explicit stack, since GLSL has no recursion: trace items, ambient hemisphere
// loops and direct-source loops. What the driver provides is listed in raytrace/core/README.md;
// the run's options are `params` (raytrace/core/parameters.h).

// Ray types as RADIANCE's ray.h numbers them; a ray's crtype is the union over its ancestry.
CONST int kPrimary = 1;
CONST int kShadow = 2;
CONST int kReflected = 4;
CONST int kRefracted = 8;
CONST int kTrans = 16;
CONST int kAmbient = 32;
CONST int kSpecular = 64;
CONST int kReflectionTypes = kShadow | kReflected | kAmbient | kSpecular;

// Rays deeper than this are dropped: pathological specular loops (-lr 0).
CONST int kMaxDepth = 200;

struct Ray {
    real3 org, dir;
    real3 coef;   // product of the coefficients from the input ray down to this ray
    real weight;  // RADIANCE's rweight
    int rlvl;     // reflections so far (for -lr)
    int crtype;   // union of the ray types of the ancestry
    int adepth;   // ambient bounces so far
    int aimed;    // for shadow rays and rays they spawn: the source aimed at (RADIANCE's rsrc)
    int depth;    // rays above it in the tree
    int from;     // the object it leaves (-1: none), which it does not meet again where it starts
    uint clip;    // antimatter bits of the modifiers it passes unseen (RADIANCE's clipset)
    uint next_clip;  // the set the rays it passes on (not reflections) start with (newcset)
#ifdef DAYFLUX_ASUB
    real dscale;  // -asub: what the diffuse paths it starts are multiplied by (1, 0 or asub^2)
    // -asub's receivers (hemisphere.inl): a deeper hemisphere's ray or a receiver sample, the
    // hemisphere's density toward it (else 0); a sample, the distance to its point (else 0) and
    // the receiver's object
    real mis;
    real target;
    int target_object;
#endif
#ifdef DAYFLUX_DIELECTRIC
    real3 cext;  // extinction of the medium it travels in (rayorigin() weighs children by it)
    real t;      // its length, where a dielectric set it
#endif
#ifdef DAYFLUX_INSIDE
    // For antimatter with a material for its inside (m_clip()'s walk up the ray tree): per
    // counted modifier, the fronts minus the backs of its surfaces that this ray and its
    // ancestors went through, leaving out reflections; 8 bits each, offset by 128.
    uvec4 inside;
    int counter;        // the counter of the surface it met (-1: none), for the rays it passes on
    int counter_front;  // and whether it met that surface's front
#endif
};

CONST int kItemTrace = 0;
CONST int kItemAmbient = 1;
CONST int kItemDirect = 2;
CONST int kItemDirectBsdf = 3;
// An item: a ray to trace, or a loop that pushes rays, at point about normal (facing r).
//   kItemAmbient: a hemisphere of n x n cells, next .. end - 1 in RADIANCE's order (i, j from
//     n - 1 down), its coefficient colour (already / n^2), its (turned) tangent.
//   kItemDirect: sources next .. end - 1 seen from a diffuse surface of colour, rdiff, tdiff and
//     trans, its rough specular colour spec and roughness squared alpha2 (0: none), flags
//     kDirect* (direct.inl).
//   kItemDirectBsdf: the same loop for a BSDF: its fields hold a BsdfDirect (direct.inl's
//     PutBsdfDirect and BsdfDirectOf, the only code that reads them as such).
struct Item {
    Ray r;
    int kind;
    real3 point, normal, colour;
    real rdiff, tdiff, trans;
    int n, next, end, flags;
    real3 spec, tangent;
    real alpha2;
    int part;   // kItemDirect*: the part of local source `next` sampled next
    uint turn;  // kItemDirect*: keys the random turn of local sources' squares
};

// Where a ray ends: a surface (the driver's Intersect fills object, surface, point, normal and
// t), or a distant source for rays that find none (source >= 0).
struct Hit {
    int object, surface, tracked, source;
    bool planar;  // a face or a ring (m_normal()'s SP_FLAT: a rough lobe widens by a source's size)
    PackedSurface m;
    real3 point, normal;
    real t;
};

// The stack: STACK_SIZE items and, last, the spare PushSlot() gives where the rest are full.
// A driver may keep it elsewhere: DRIVER_STACK_STORAGE declares that storage (after Item, which
// it holds) and STACK(i) names item i there. The GPU's does, since NVIDIA's driver refuses
// pipelines whose private arrays pass about 16 KiB an invocation.
#ifdef DRIVER_STACK_STORAGE
DRIVER_STACK_STORAGE
#else
Item stack[STACK_SIZE + 1];
#define STACK(i) stack[i]
#endif
int top;
uint dropped;  // items that did not fit, over the driver's run (it reads and clears it)
uint reports;  // tables.h's kReport* flags, likewise

// The slot of a new item on the stack: its fields are written there, not copied in. Where the
// stack is full, the spare slot past its end, which is never read: the item is dropped, and
// counted.
int PushSlot() {
    if (top < STACK_SIZE) return top++;
    ++dropped;
    reports |= kReportStackFull;
    return STACK_SIZE;
}
// Takes back the slot of an item that came to nothing (its ray died), pushed last.
void Unpush(int at) {
    if (at < STACK_SIZE) --top;
}

// ---- random numbers (random.h): the state of the path being traced
uint rng;
uint cell_key;  // the key of the input ray (seed, ray, replica), then of its first-level cell
uint turn_key;  // the key of its first-level grids' turns (seed, ray, TurnReplica(replica))
real Rand() {
    rng = Pcg(rng);
    return UnitInterval(rng);
}

#ifdef __cplusplus
double cal_chan[28];  // GLSL: declared by the generated calcomp code
#endif

// The ray variables $1..$27 (rayinit.cal) for the bins and patterns: direction, normal, point
// (world), distance, Rdot, scale, identity transform.
void SetRayVariablesAlong(real3 dir, real3 point, real3 normal, real t) {
    cal_chan[1] = dir.x;
    cal_chan[2] = dir.y;
    cal_chan[3] = dir.z;
    cal_chan[4] = normal.x;
    cal_chan[5] = normal.y;
    cal_chan[6] = normal.z;
    // (on the CPU the rest is 0, and this is the point plus the centre)
    cal_chan[7] = cal_real(point.x) + (cal_real(params.centre_rest_x) + cal_real(params.centre_x));
    cal_chan[8] = cal_real(point.y) + (cal_real(params.centre_rest_y) + cal_real(params.centre_y));
    cal_chan[9] = cal_real(point.z) + (cal_real(params.centre_rest_z) + cal_real(params.centre_z));
    cal_chan[10] = t;
    cal_chan[11] = -dot(dir, normal);
    cal_chan[12] = 1;
    for (int i = 13; i <= 27; ++i) cal_chan[i] = 0;
    cal_chan[16] = 1;
    cal_chan[20] = 1;
    cal_chan[24] = 1;
}
void SetRayVariables(IN(Ray) r, real3 point, real3 normal, real t) {
    SetRayVariablesAlong(r.dir, point, normal, t);
}

// A material's colour at a hit, times its pattern. (Antimatter keeps its inside counters where
// others keep their pattern, and has no colour: a tracked one gives 0 with -V+.)
real3 Colour(IN(PackedSurface) m, IN(Ray) r, real3 point, real3 normal, real t) {
    if (m.pattern < 0 || m.kind == kMatAntimatter) return XYZ(m.color);
    SetRayVariables(r, point, normal, t);
    return XYZ(m.color) * real3(PatternRGB(m.pattern));
}

// A shaded ray's contribution, kept until its shading is done (AddContribution): a ray makes one
// at most, and adding it from one place evaluates the bins in one place, where a GPU compiler
// would copy every bin function into each call of Contribute.
struct PendingContribution {
    int k, source;  // the tracked modifier, and the distant source reached (or -1)
    real3 dir, point, normal, value;
    real t;
};
PendingContribution pending_contribution;
bool contribution_pending = false;

// Ray r's contribution to tracked modifier k's bin (AddContribution adds it): its coefficient,
// times radiance with -V.
void Contribute(int k, IN(Ray) r, IN(real3) point, IN(real3) normal, real t, int source,
                IN(real3) radiance) {
    pending_contribution.k = k;
    pending_contribution.source = source;
    pending_contribution.dir = r.dir;
    pending_contribution.point = point;
    pending_contribution.normal = normal;
    pending_contribution.value = params.contributions != 0 ? r.coef * radiance : r.coef;
    pending_contribution.t = t;
    contribution_pending = true;
}

// Adds the pending contribution to the bin its modifier's bin expression gives. Negative bins
// are ignored, as RADIANCE ignores them; one beyond -bn, or NaN, is reported and ignored, checked
// before int() because int() of one beyond the int range is undefined (INT_MIN on x86, a write
// before the record).
void AddContribution() {
    if (!contribution_pending) return;
    contribution_pending = false;
    PendingContribution c = pending_contribution;
    SetRayVariablesAlong(c.dir, c.point, c.normal, c.t);
    ivec4 entry = tracked[c.k];
    cal_real b = BinOf(c.k, c.source);
    if (b <= -0.5) return;
    if (!(b < cal_real(entry[kTrackedBins]) - 0.5)) {
        reports |= kReportBadBin;
        return;
    }
    int bin = int(floor(b + 0.5));
    AddToRecord(entry[kTrackedColumn] + bin, c.value);
}

#ifdef DAYFLUX_INSIDE
int InsideCount(uvec4 inside, int counter) {
    return int((inside[counter >> 2] >> uint(8 * (counter & 3))) & 255u) - 128;
}
void InsideAdd(INOUT(uvec4) inside, int counter, int delta) {
    uint shift = uint(8 * (counter & 3));
    uint count = uint(clamp(InsideCount(inside, counter) + delta, -128, 127) + 128);
    inside[counter >> 2] = (inside[counter >> 2] & ~(255u << shift)) | (count << shift);
}
#endif

// The ray an input ray starts: a primary ray from org along dir (rayorigin() without a parent).
Ray PrimaryRay(real3 org, real3 dir) {
    Ray r;
    r.org = org;
    r.dir = dir;
    r.coef = real3(1);
    r.weight = 1.;
    r.rlvl = 0;
    r.crtype = kPrimary;
    r.adepth = 0;
    r.aimed = -1;
    r.depth = 0;
    r.from = -1;
    r.clip = 0u;
    r.next_clip = 0u;
#ifdef DAYFLUX_ASUB
    r.dscale = 1.0;
    r.mis = 0.;
    r.target = 0.;
    r.target_object = -1;
#endif
#ifdef DAYFLUX_DIELECTRIC
    r.cext = real3(0);
    r.t = 0.;
#endif
#ifdef DAYFLUX_INSIDE
    r.inside = uvec4(0x80808080u);
    r.counter = -1;
    r.counter_front = 0;
#endif
    return r;
}

// Every other ray is made here: rayorigin()'s child of parent, of ray type `type` (joined to its
// ancestry's), carrying coefficient rc (coef: the product down the tree; weight: times rc's
// largest part, at most 1, and the extinction over the parent's length in a medium). A
// reflection resets the source aimed at and keeps the clip set; a ray passed on takes the set
// the parent left it. The caller sets its origin and direction, and asks Survives() where
// rayorigin()'s verdict counts (direct() and a mirror's relay of a shadow ray ignore it).
void ChildRay(IN(Ray) parent, int type, real3 rc, OUT(Ray) child) {
    bool reflected = (type & kReflectionTypes) != 0;
    child = parent;
    child.depth = parent.depth + 1;
    child.rlvl = parent.rlvl + (reflected ? 1 : 0);
    child.crtype = parent.crtype | type;
    child.weight = parent.weight * min(1.0, Max3(rc));
    child.coef = parent.coef * rc;
    child.aimed = reflected ? -1 : parent.aimed;
    child.clip = reflected ? parent.clip : parent.next_clip;
    child.next_clip = child.clip;
#ifdef DAYFLUX_ASUB
    child.mis = 0.;  // set where a hemisphere makes it
    child.target = 0.;
    child.target_object = -1;
#endif
#ifdef DAYFLUX_INSIDE
    if (!reflected && parent.counter >= 0)
        InsideAdd(child.inside, parent.counter, parent.counter_front != 0 ? 1 : -1);
    child.counter = -1;
#endif
#ifdef DAYFLUX_DIELECTRIC
    child.t = 0.;
    real re = min(parent.cext.x, min(parent.cext.y, parent.cext.z)) * parent.t;
    if (re > 0.1) child.weight = re > 92.0 ? 0.0 : child.weight * exp(-re);
#endif
}

// rayorigin()'s verdict on a child: false where it dies (no weight; beyond -lr; Russian roulette
// below -lw with -lr <= 0, a survivor's coefficient raised). Shadow rays are never cut short.
bool Survives(INOUT(Ray) child) {
    if (child.weight <= 0.) return false;
    if ((child.crtype & kShadow) != 0) return true;
    if (params.lr <= 0) {
        if (params.lr < 0 && child.rlvl > -params.lr) return false;
        if (child.weight >= params.lw) return true;
        if (Rand() > child.weight / params.lw) return false;
        child.coef *= real(params.lw) / child.weight;
        child.weight = real(params.lw);
        return true;
    }
    return child.weight >= params.lw && child.rlvl <= params.lr;
}

// rayorigin(): a child (ChildRay) where it survives; false if it dies.
bool Spawn(IN(Ray) parent, int type, real3 rc, OUT(Ray) child) {
    ChildRay(parent, type, rc, child);
    return Survives(child);
}

void PushItem(IN(Item) it) { STACK(PushSlot()) = it; }

void PushTrace(IN(Ray) r) {
    int at = PushSlot();
    STACK(at).r = r;
    STACK(at).kind = kItemTrace;
}

// A child ray from org along dir, if rayorigin() lets it live (spawned in its slot); whether it
// did.
bool PushChild(IN(Ray) r, int type, IN(real3) coef, IN(real3) org, IN(real3) dir) {
    int at = PushSlot();
    if (!Spawn(r, type, coef, STACK(at).r)) {
        Unpush(at);
        return false;
    }
    STACK(at).r.org = org;
    STACK(at).r.dir = dir;
    STACK(at).kind = kItemTrace;
    return true;
}

// sourcehit(): a ray that meets no surface reaches the first distant source whose disc holds its
// direction (a ray aimed at a source can reach only that one), a glow only where no other does.
bool Escape(IN(Ray) r, OUT(Hit) h) {
    int glow = -1, chosen = -1;
    int first = r.aimed >= 0 ? r.aimed : 0, last = r.aimed >= 0 ? r.aimed + 1 : params.nsources;
    for (int i = first; i < last; ++i) {
        // images in mirrors are not met
        if (int(sources[i].u.w) != kSourceDistant || sources[i].relay >= 0) continue;
        real c = dot(XYZ(sources[i].dir), r.dir);
        if (2. * kPi * (1. - c) > real(sources[i].dir.w)) continue;
        if (sources[i].colour.w > 0.5 && r.aimed < 0) {
            if (glow < 0) glow = i;
            continue;
        }
        chosen = i;
        break;
    }
    if (chosen < 0) chosen = glow;
    if (chosen < 0) return false;
    LOCAL(PackedSource) s = sources[chosen];
    h.object = s.object;
    h.surface = -1;
    h.tracked = s.tracked;
    h.source = chosen;
    h.planar = false;
    h.m.color = vec4(s.colour.x, s.colour.y, s.colour.z, 0);
    h.m.params = vec4(0);
    h.m.alpha2 = 0.;
    h.m.pattern = s.pattern;
    h.m.kind = s.kind;
    h.m.tracked = s.tracked;
    h.m.fore = -1;
    h.m.back = -1;
    h.m.clip = 0u;
    h.m.counter = -1;
    h.point = r.dir * 1e30;
    h.normal = -r.dir;
    h.t = 1e30;
    return true;
}

#ifdef DAYFLUX_ASUB
// -asub: a first-level sub-sample starts the diffuse paths of its cell (scale asub^2) or none
// (0); false for none.
bool ScaleForDiffuse(INOUT(Ray) r) {
    if (r.dscale == 0.0) return false;
    r.coef *= r.dscale;
    r.dscale = 1.0;
    return true;
}
#endif
