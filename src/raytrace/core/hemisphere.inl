// Ambient hemispheres (a fragment: see language.h): n x n cosine-weighted, stratified samples of
// the hemisphere about a normal, each carrying colour / n^2, with
// n = sqrt(ad * min(weight, 0.8 rho weight / (ad lw))) as RADIANCE's samp_hemi() computes it with
// -aa 0, and -asub's sub-sampled first hemispheres (ours).
//
// RADIANCE's ambcollision(): a direction within a quarter division of an earlier neighbour's is
// drawn again in its cell. This moves samples away from their neighbours (so its estimate differs
// from plain stratified sampling in the percent range for light arriving at grazing angles); we
// match it. The neighbours already drawn are (i, j + 1) and the row before, so each hemisphere
// keeps two rows of directions: row i in slot i & 1. One hemisphere per ambient depth is active at
// a time (the stack finishes a hemisphere's cells before a sibling's), so the rows are kept per
// depth: up to MAXN cells a side at depth 0, DEEP_N below it, for the first DEEP_LEVELS depths
// (beyond those, no collision rule: the GPU's defaults are small, since deeper hemispheres rarely
// have more than 2 cells a side).
// The first hemisphere's cells have random numbers keyed by the cell, so a task tracing some of
// its rows replays the directions of the rows before them without tracing them.

uint pushed0;       // first-level hemispheres pushed for this input ray (random-number keys)
uint hemispheres0;  // first-level hemispheres started, likewise
// The first level's steps before this one are replayed, not traced (a slice's rows are not
// the first: InputCells); their rays are dropped as they are pushed (Replayed).
int steps_replayed = 0;

// Whether hemisphere item it's last step was one replayed (its ray, if pushed, to be dropped).
bool Replayed(IN(Item) it) { return it.r.adepth == 0 && it.next <= steps_replayed; }
// The rows: ROW0(i) of the first level's 2 MAXN, ROWD(i) of the deeper levels' 2 DEEP_N each;
// a driver may keep them elsewhere by defining both (the GPU's does: see STACK in rays.inl).
#ifndef ROW0
real3 rows0[2 * MAXN];
real3 rowsd[DEEP_LEVELS * 2 * DEEP_N];
#define ROW0(i) rows0[i]
#define ROWD(i) rowsd[i]
#endif

// A point of the unit disk in the tangent plane (ux, uy) lifted to the hemisphere about normal:
// uniform points give cosine-weighted directions.
real3 DiskToHemisphere(real2 xy, real3 ux, real3 uy, real3 normal) {
    real z = sqrt(max(0.0, 1. - dot(xy, xy)));
    return CheckNorm(xy.x * ux + xy.y * uy + z * normal);
}

#ifdef DAYFLUX_ASUB
// -asub below the first hemisphere: a diffuse surface there also samples the receivers directly
// (the glow triangles of tables.h's receivers table: a V matrix's window), a point on them picked
// by area beside each of its hemisphere's rays (up to kReceiverSamples), as RADIANCE's direct
// calculation samples light sources. Where a sample's ray meets its point, it counts with the
// balance heuristic's share, and so does each of the hemisphere's rays that meets a receiver
// straight away (multiple importance sampling: the two shares add to one for every direction,
// so the sum stays unbiased, and the light a window sends in reaches each surface of the room
// with far less noise than its few hemisphere rays alone bring). A ray reaching a receiver
// through anything else (glass, a mirror) keeps its whole coefficient: a sample counts only
// where nothing lies between. The hemisphere's density is taken as the cosine's: where
// RADIANCE's collision rule moves its rays (n > 1), it moves only the hemisphere's share.

CONST int kReceiverSamples = 4;  // at most, per hemisphere: each waits on the stack

bool SamplesReceivers(int adepth) { return params.asub > 1 && adepth > 0 && receivers[0].y > 0.; }
int ReceiverSamples(int cells) { return min(cells, kReceiverSamples); }

// The density of a hemisphere of `cells` rays toward dir per unit solid angle, per receiver
// sample taken beside it (so that both are per sample; the hemisphere's cosine density times
// cells / samples). Never nought for a ray it made: Shade weighs the rays whose density is
// above nought.
real HemisphereDensity(int cells, real3 dir, real3 normal) {
    return max(real(cells) / real(ReceiverSamples(cells)) * dot(dir, normal) / kPi, kTiny);
}

// The receivers' density toward a point at distance t whose surface the direction meets at
// cosine cos_there, per unit solid angle.
real ReceiverDensity(real t, real cos_there) {
    return t * t / (real(receivers[0].x) * max(cos_there, kTiny));
}

// The share a hemisphere ray (its density r.mis) keeps where it meets a receiver at distance t.
real HemisphereShare(IN(Ray) r, real t, real cos_there) {
    return r.mis / (r.mis + ReceiverDensity(t, cos_there));
}

// A point of the receivers, picked by area, seen from point on a surface of colour whose
// hemisphere has `cells` rays: a ray toward it pushed (ReceiverSampleMet counts it), spawned as
// the hemisphere's rays are (rayorigin()'s limits and roulette), its coefficient times cos / pi,
// with the hemisphere's density toward it, the distance to it and the receiver's object.
void SampleReceiver(IN(Ray) r, IN(real3) colour, IN(real3) point, IN(real3) normal, int cells) {
    int count = int(receivers[0].y);
    real pick = Rand() * real(receivers[0].x);
    int lo = 0, hi = count - 1;  // the first triangle whose cumulative area passes pick
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (real(receivers[1 + 3 * mid].w) <= pick)
            lo = mid + 1;
        else
            hi = mid;
    }
    real a = Rand(), b = Rand();
    if (a + b > 1.) {
        a = 1. - a;
        b = 1. - b;
    }
    int tri = 1 + 3 * lo;
    real3 to = real3(XYZ(receivers[tri])) + a * real3(XYZ(receivers[tri + 1])) +
               b * real3(XYZ(receivers[tri + 2])) - point;
    real dist = length(to);
    if (dist <= kTiny) return;
    real3 dir = to / dist;
    real cos_here = dot(dir, normal);
    if (cos_here <= kTiny) return;
    int at = PushSlot();
    // spawned as a hemisphere ray (so that -lr and -lw stop it as they stop those), then
    // carrying the colour / samples
    if (!Spawn(r, kAmbient, colour / real(cells), STACK(at).r)) {
        Unpush(at);
        return;
    }
    STACK(at).kind = kItemTrace;
    STACK(at).r.org = point;
    STACK(at).r.dir = dir;
    STACK(at).r.coef *= real(cells) / real(ReceiverSamples(cells)) * cos_here / kPi;
    STACK(at).r.mis = HemisphereDensity(cells, dir, normal);
    STACK(at).r.target = dist;
    STACK(at).r.target_object = int(receivers[tri + 1].w);
}

// (A two-sided surface's samples behind wait under its front hemisphere: at most four items.)
void SampleReceivers(IN(Ray) r, IN(real3) colour, IN(real3) point, IN(real3) normal, int cells) {
    for (int k = 0; k < ReceiverSamples(cells); ++k)
        SampleReceiver(r, colour, point, normal, cells);
}

// A receiver sample's ray (r.target > 0) met what h holds (if met): where that is its point on
// its object (within 0.1 %: positions are float on the GPU), its contribution, the estimate's
// share of it: colour cos / pi / the receivers' density, times that density over the sum of both.
void ReceiverSampleMet(IN(Ray) r, bool met, IN(Hit) h) {
    if (!met || h.object != r.target_object || abs(h.t - r.target) > 1e-3 * r.target) return;
    PackedSurface m = surfaces[h.surface];
    if ((int(m.params.w) & kSurfaceSampled) == 0) return;
    real cos_there = -dot(r.dir, h.normal);
    real3 facing = cos_there < 0. ? -h.normal : h.normal;
    cos_there = abs(cos_there);
    if (cos_there <= kTiny) return;
    Ray c = r;
    c.coef /= ReceiverDensity(h.t, cos_there) + r.mis;
    Contribute(m.tracked, c, h.point, facing, h.t, -1,
               params.contributions != 0 ? Colour(m, c, h.point, facing, h.t) : real3(1));
}
#endif

// A deeper hemisphere of one cell (most of them: the weights below the first level are small):
// its ray pushed at once, as AmbientStep would push it, in any tangent frame. The random turn
// matters only to the collision rule between cells; one cell's direction is cosine-distributed
// about the normal whatever the frame. (Its random numbers differ: Spawn's and the cell's are
// drawn before those of rays pushed after it, and the turn's four are not drawn.)
void PushSingleCell(IN(Ray) r, IN(real3) colour, IN(real3) point, IN(real3) normal) {
    int at = PushSlot();
    if (!Spawn(r, kAmbient, colour, STACK(at).r)) {
        Unpush(at);
        return;
    }
    STACK(at).r.adepth = r.adepth + 1;
    real3 ux, uy;
    Tangents(normal, ux, uy);
    real u = Rand(), v = Rand();
    STACK(at).r.org = point;
    STACK(at).r.dir = DiskToHemisphere(SquareToDisk(v, u), ux, uy, normal);
    STACK(at).kind = kItemTrace;
#ifdef DAYFLUX_ASUB
    if (SamplesReceivers(r.adepth)) STACK(at).r.mis = HemisphereDensity(1, STACK(at).r.dir, normal);
#endif
}

void PushHemisphere(IN(Ray) ray, IN(real3) colour, IN(real3) point, IN(real3) normal) {
    if (ray.adepth >= params.ab || params.ad <= 0) return;
    if (Bright(colour) <= kTiny) return;
#if defined(DAYFLUX_ASUB) || !defined(__cplusplus)
    Ray r = ray;
#else
    const Ray &r = ray;  // not copied where not changed: the CPU's copy cost 2.5 % of a run
#endif
#ifdef DAYFLUX_ASUB
    if (!ScaleForDiffuse(r)) return;
#endif
    real wt = r.weight;
    real d = 0.8 * Max3(colour) * r.weight / real(params.ad * params.lw);
    if (wt > d) wt = d;
    int n = int(sqrt(real(params.ad) * wt) + 0.5);
    if (n < 1) n = 1;
    if (n == 1 && r.adepth > 0) {
        PushSingleCell(r, colour, point, normal);
#ifdef DAYFLUX_ASUB
        if (SamplesReceivers(r.adepth)) SampleReceivers(r, colour, point, normal, 1);
#endif
        return;
    }
    // The grid's turn: at the first level from numbers keyed by the hemisphere, so that every
    // slice of a sensor's hemisphere turns it the same way (and both replicas of a pair).
    uint saved = rng;
    if (r.adepth == 0) rng = Key(turn_key, ++pushed0, 0x2545f491u, 7u);
    real t0 = Rand(), t1 = Rand(), t2 = Rand(), t3 = Rand();
    if (r.adepth == 0) rng = saved;
    int at = PushSlot();
    STACK(at).r = r;
    STACK(at).kind = kItemAmbient;
    STACK(at).point = point;
    STACK(at).normal = normal;
    STACK(at).colour = colour / real(n * n);
    STACK(at).n = n;
    STACK(at).next = 0;
    STACK(at).end = n * n;
#ifdef DAYFLUX_ASUB
    if (r.adepth == 0) STACK(at).end *= params.asub * params.asub;  // steps: the cells' sub-samples
#endif
    STACK(at).tangent = RandomTangent(normal, t0, t1, t2, t3);
#ifdef DAYFLUX_ASUB
    // (above the hemisphere: traced first, they spawn nothing, so the stack stays as deep)
    if (SamplesReceivers(r.adepth)) SampleReceivers(r, colour, point, normal, n * n);
#endif
}

bool CollisionRule(int depth, int n) {
    return n > 1 && (depth == 0 ? n <= MAXN : depth <= DEEP_LEVELS && n <= DEEP_N);
}
real3 RowDir(int depth, int slot, int j) {
    return depth == 0 ? ROW0(slot * MAXN + j) : ROWD(((depth - 1) * 2 + slot) * DEEP_N + j);
}
void SetRowDir(int depth, int slot, int j, real3 d) {
    if (depth == 0)
        ROW0(slot * MAXN + j) = d;
    else
        ROWD(((depth - 1) * 2 + slot) * DEEP_N + j) = d;
}

// Cell (i, j) of hemisphere item it divided n x n: its ray's coefficient and a direction in the
// cell, drawn again (up to 1000 times) while it collides with a neighbour's when check is set.
bool CellDirection(IN(Item) it, int n, int i, int j, real cos_thresh, bool check, OUT(Ray) child,
                   OUT(real3) dir) {
    if (!Spawn(it.r, kAmbient, it.colour, child)) return false;
    child.adepth = it.r.adepth + 1;
    real3 ux = it.tangent, uy = cross(it.normal, ux);
    int d = it.r.adepth, cur = i & 1, prev = (i + 1) & 1;
    real u = Rand(), v = Rand();
    for (int tries = 0;; ++tries) {
        dir = DiskToHemisphere(SquareToDisk((real(j) + v) / real(n), (real(i) + u) / real(n)), ux,
                               uy, it.normal);
        if (!check || tries == 1000) break;
        bool hit = (j + 1 < n && dot(RowDir(d, cur, j + 1), dir) >= cos_thresh) ||
                   (i + 1 < n && ((j > 0 && dot(RowDir(d, prev, j - 1), dir) >= cos_thresh) ||
                                  dot(RowDir(d, prev, j), dir) >= cos_thresh ||
                                  (j + 1 < n && dot(RowDir(d, prev, j + 1), dir) >= cos_thresh)));
        if (!hit) break;
        u = Rand();
        v = Rand();
    }
    return true;
}

#ifdef DAYFLUX_ASUB
// -asub: step k of a first-level hemisphere is sub-sample k % asub^2 of cell k / asub^2, in the
// cell's asub x asub sub-cells; all follow their specular paths (what reaches a window, or the
// sky through glass, directly), and one chosen at random per cell carries the cell's diffuse
// paths with asub^2 times its coefficient. Unbiased; no ambcollision() (the sub-samples
// stratify the cell instead).
// Only cells near something a specular path could start from are split: a probe along each
// cell's centre finds what the cell looks at, and a cell whose 3 x 3 neighbourhood's probes all
// meet bare diffuse surfaces (InertForSubsamples) keeps one ray, the chosen sub-sample with the
// whole cell's coefficient and diffuse paths (so uniform over the cell). The probes depend on the
// hemisphere's turn alone, never on the cells' own random numbers: still unbiased.
// The probes' answers are kept for three rows (a ring: row i's in component i % 3 of ROW0(j),
// which row a component holds in ROW0(MAXN + i % 3).x), in the collision rule's rows, which these
// cells do not use.

// Whether what a probe met starts no specular path and counts for nothing itself: black, or
// plastic and metal without specularity or transmission, tracked by no modifier, clipped by no
// antimatter.
bool InertForSubsamples(LOCAL(PackedSurface) m) {
    if (m.tracked >= 0 || m.clip != 0u) return false;
    return m.kind == kMatBlack || (m.kind == kMatDiffuse && m.params.x == 0. && m.params.y == 0.);
}

// Whether the probe along cell (i, j)'s centre meets something other than an inert surface (a
// distant source or glow included).
bool ProbeMeetsTarget(IN(Item) it, int i, int j) {
    Ray probe = it.r;
    probe.org = it.point;
    probe.dir =
        DiskToHemisphere(SquareToDisk((real(j) + 0.5) / real(it.n), (real(i) + 0.5) / real(it.n)),
                         it.tangent, cross(it.normal, it.tangent), it.normal);
    probe.aimed = -1;
    Hit h;
    if (!Intersect(probe, h)) return Escape(probe, h);
    return !InertForSubsamples(surfaces[h.surface]);
}

void ForgetProbes() {
    if (MAXN < 3) return;  // no room for the tags: WorthSubsampling splits every cell
    for (int slot = 0; slot < 3; ++slot) ROW0(MAXN + slot) = real3(-1.);
}

// Row i's probe at column j, the row probed first where the ring does not hold it.
bool Probed(IN(Item) it, int i, int j) {
    int slot = i % 3;
    if (ROW0(MAXN + slot).x != real(i)) {
        for (int x = 0; x < it.n; ++x) {
            real3 flags = ROW0(x);
            flags[slot] = ProbeMeetsTarget(it, i, x) ? 1. : 0.;
            ROW0(x) = flags;
        }
        ROW0(MAXN + slot) = real3(real(i));
    }
    real3 flags = ROW0(j);
    return flags[slot] != 0.;
}

bool WorthSubsampling(IN(Item) it, int i, int j) {
    if (it.n > MAXN || MAXN < 3) return true;  // no room for the probes
    // The rim's cells hold the lowest quarter of the sky's elevations at n = 22 (cosine
    // weighting crowds the horizon there): a window seen from across a room can be a band there
    // thinner than a cell, which a probe at its centre misses.
    if (min(i, j) == 0 || max(i, j) == it.n - 1) return true;
    for (int a = max(0, i - 1); a <= min(it.n - 1, i + 1); ++a)
        for (int b = max(0, j - 1); b <= min(it.n - 1, j + 1); ++b)
            if (Probed(it, a, b)) return true;
    return false;
}

// What step 0 of a first-level hemisphere does before its ray (a task starting at a later row
// does it instead of replaying the steps before).
void StartSubsamples() {
    ++hemispheres0;
    ForgetProbes();
}

// Returns true if it pushed the step's ray. A cell is decided at its first step: split, its
// other steps follow; left whole, its chosen step is taken at once and the others skipped
// (it.next moves to the next cell's first step).
bool SubsampleStep(INOUT(Item) it, int k) {
    int per = params.asub * params.asub;
    int cell = k / per, s = k % per;
    int i = it.n - 1 - cell / it.n, j = it.n - 1 - cell % it.n;
    if (k == 0) StartSubsamples();
    rng = Key(cell_key, uint(cell), 0x85ebca6bu, hemispheres0);  // the same for the cell's steps
    int chosen = min(per - 1, int(Rand() * real(per)));
    bool split = s > 0 || WorthSubsampling(it, i, j);
    if (!split) {
        s = chosen;
        k = cell * per + s;
        it.next = (cell + 1) * per;
    }
    rng = Key(cell_key, uint(k), 0x9e3779b9u, hemispheres0);
    int at = PushSlot();  // the sub-sample's ray, spawned in its slot
    real3 dir;
    if (!CellDirection(it, it.n * params.asub, i * params.asub + s / params.asub,
                       j * params.asub + s % params.asub, 0.0, false, STACK(at).r, dir)) {
        Unpush(at);
        return false;
    }
    if (split) {
        STACK(at).r.coef /= real(per);
        STACK(at).r.dscale = s == chosen ? real(per) : 0.0;
    } else {
        STACK(at).r.dscale = 1.0;
    }
    STACK(at).r.org = it.point;
    STACK(at).r.dir = dir;
    STACK(at).kind = kItemTrace;
    return true;
}
#endif

// The next step of hemisphere item it; returns true if it pushed the cell's ray.
bool AmbientStep(INOUT(Item) it) {
    // Cells in RADIANCE's order: k = 0 is (n - 1, n - 1), then j, then i, downward.
    int k = it.next++;
#ifdef DAYFLUX_ASUB
    if (it.r.adepth == 0 && params.asub > 1) return SubsampleStep(it, k);
#endif
    int i = it.n - 1 - k / it.n, j = it.n - 1 - k % it.n;
    int d = it.r.adepth;
    bool rule = CollisionRule(d, it.n);
    real spacing = (kPi / 4.) / real(it.n);
    real cos_thresh = 1. - .5 * spacing * spacing;
    if (rule && j == it.n - 1)  // a new row: its slot is emptied
        for (int x = 0; x < it.n; ++x) SetRowDir(d, i & 1, x, real3(0));
    if (d == 0) {
        // The cell's own random numbers (and those of the path it starts), so that any task
        // can replay it.
        if (k == 0) ++hemispheres0;
        rng = Key(cell_key, uint(k), 0x9e3779b9u, hemispheres0);
    }
    int at = PushSlot();  // the cell's ray, spawned in its slot
    real3 dir;
    bool ok = CellDirection(it, it.n, i, j, cos_thresh, rule, STACK(at).r, dir);
    if (rule) SetRowDir(d, i & 1, j, ok ? dir : real3(0));
    if (!ok) {
        Unpush(at);
        return false;
    }
#ifdef DAYFLUX_ASUB
    if (SamplesReceivers(d)) STACK(at).r.mis = HemisphereDensity(it.n * it.n, dir, it.normal);
#endif
    STACK(at).r.org = it.point;
    STACK(at).r.dir = dir;
    STACK(at).kind = kItemTrace;
    return true;
}
