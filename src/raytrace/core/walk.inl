// The walk of RADIANCE's ray tree from one input ray (a fragment: see language.h): items popped
// from the stack until none is left, a trace item finding what its ray meets (the driver's
// Intersect) and shading it, hemisphere and direct items taking their next step.

// Runs the stack's hemisphere and direct items until a ray to trace is on top, and pops it: its
// slot `at` holds it until the next push (a driver may read it there later, rather than copy it
// at once: on the CPU a copy of a ray just written stalled on store forwarding); false once the
// stack is empty. Hemisphere and direct items stay on the stack while they have cells or sources
// left, under the rays their steps push, which run first.
bool NextRay(OUT(int) at) {
    while (top > 0) {
        int kind = STACK(top - 1).kind;
        if (kind == kItemTrace) {
            at = --top;
            if (STACK(at).r.depth > kMaxDepth) continue;
            return true;
        } else if (kind == kItemAmbient) {
            int item = top - 1;
            bool pushed = AmbientStep(STACK(item));  // (-asub's may skip a cell's other steps)
            if (pushed && Replayed(STACK(item))) {
                --top;  // a row before the slice's: its direction replayed, its ray dropped
                pushed = false;
            }
            if (STACK(item).next >= STACK(item).end) {
                // the hemisphere leaves the stack, its last cell's ray takes its place
                if (pushed) {
                    STACK(item).r = STACK(item + 1).r;
                    STACK(item).kind = kItemTrace;
                }
                --top;
            }
        } else {  // kItemDirect, kItemDirectBsdf
            int item = top - 1;
            if (STACK(item).next >= STACK(item).end) {  // its last step's shadow ray has run
                --top;
                continue;
            }
            if (!DirectItemStep(STACK(item)) && top == item + 1) --top;
        }
    }
    return false;
}

// Ray r (a copy of the one NextRay popped: what r spawns is pushed over its slot) meets what the
// driver's Intersect found (met, in h) or else a distant source (sourcehit()), and that is
// shaded, pushing what it spawns; its contribution, if any, is left pending (ShadeMet adds it).
void ShadeHit(INOUT(Ray) r, bool met, INOUT(Hit) h) {
#ifdef DAYFLUX_ASUB
    if (r.target > 0.) {
        ReceiverSampleMet(r, met, h);
        return;
    }
#endif
    if (met) {
        h.m = surfaces[h.surface];
        h.tracked = h.m.tracked;
        h.source = -1;
    } else if (!Escape(r, h)) {
        return;
    }
#ifdef DAYFLUX_DIELECTRIC
    if (Max3(r.cext) > 0.) r.t = h.t;  // its length, for the weights of its children
#endif
#ifdef DAYFLUX_INSIDE
    r.counter = h.m.counter;
    r.counter_front = dot(r.dir, h.normal) < 0. ? 1 : 0;
#endif
    if ((r.clip & h.m.clip) != 0u) {
        // raycont(): antimatter hides the surface; rcontrib's trace_contrib() still sees the
        // hit, so a tracked modifier counts its coefficient (no value for -V).
        if (h.tracked >= 0 && params.contributions == 0 &&
            (r.aimed < 0 || h.object == sources[r.aimed].object))
            Contribute(h.tracked, r, h.point, h.normal, h.t, h.source, real3(1));
        r.from = h.object;
        PushChild(r, kTrans, real3(1), h.point, r.dir);
        return;
    }
    Shade(r, h);
}

// A traced ray shaded (ShadeHit), then its contribution added.
void ShadeMet(INOUT(Ray) r, bool met, INOUT(Hit) h) {
    ShadeHit(r, met, h);
    AddContribution();
}

// The walk: each ray the stack gives traced (the driver's Intersect) and shaded. (The GPU's
// driver has a loop of its own, the same three calls: contrib.comp's Run.)
void RunStack() {
    int at;
    while (NextRay(at)) {
        Hit h;
        bool met = Intersect(STACK(at).r, h);
        Ray r = STACK(at).r;
        ShadeMet(r, met, h);
    }
}

// The point an -I input ray's surface lies at: RADIANCE offsets it by 1e-4 along the normal
// (PRECISE: both steps compute it, and must get the same bits).
real3 InputPoint(real3 org, real3 dir) {
    PRECISE real3 point = org + 1e-4 * dir;
    return point;
}

// Input ray `index` (org, dir of unit length) of replica `replica` (-se) is traced in two steps,
// the stack walked (RunStack) after each, its contributions added through AddToRecord: StartInput
// readies its keys and pushes its share of the light sources (thousands of suns for C_ds), or,
// without -I, the ray itself; InputCells then pushes its first hemisphere (-I) and gives back
// the cells still to trace. A sensor's first hemisphere may be shared between tasks: this one
// traces its rows of slice `slice` of `slices`, replaying the directions of the rows before them
// without tracing them, and its share of the sources, their samples keyed as in one task. The
// steps are apart because a GPU compiler inlines every call of RunStack, and all the shading
// code with it: the GPU's driver walks from one place (contrib.comp). (The CPU's TraceSlices
// takes each slice's sources with StartInput, then the hemisphere whole: StepsPerSlice.)
void StartInput(real3 org, real3 dir, uint index, uint replica, uint slice, uint slices) {
    top = 0;
    pushed0 = 0u;
    hemispheres0 = 0u;
    steps_replayed = 0;
    cell_key = Key(params.seed, index, replica, 0x2545f491u);
    turn_key = Key(params.seed, index, TurnReplica(replica), 0x2545f491u);
    Ray r = PrimaryRay(org, dir);
    if (params.irradiance == 0) {
        rng = Key(cell_key, slice, 17u, 5u);
        if (slice == 0u) PushTrace(r);
        return;
    }
    // -I: a Lambertian surface of reflectance pi at the origin, facing the ray direction, so
    // that the ambient value is irradiance.
    int per_slice = (params.nsources + int(slices) - 1) / int(slices);
    int source_first = int(slice) * per_slice;
    if (source_first >= params.nsources) return;
    rng = Key(cell_key, 0u, 17u, 5u);  // slice 0's: the direct item turns alike in all
    PushDirect(r, real3(kPi), 1.0, 0.0, 0.0, 0, InputPoint(org, dir), dir, real3(0), 0.0);
    if (top > 0) {
        STACK(top - 1).next = source_first;
        STACK(top - 1).end = min(params.nsources, source_first + per_slice);
    }
}

// How InputCells shares a first hemisphere's rows out between slices: a slice's rows, and a
// row's steps (-asub's sub-samples each a step).
int RowsPerSlice(int rows, uint slices) { return (rows + int(slices) - 1) / int(slices); }
int StepsPerRow(IN(Item) h) {
#ifdef DAYFLUX_ASUB
    if (params.asub > 1) return h.n * params.asub * params.asub;
#endif
    return h.n;
}
// The steps of each of first hemisphere h's `slices` slices: step k is in slice k / that. For a
// driver that traces the hemisphere whole and keeps its slices' sums apart (the CPU's
// TraceSlices), rather than a task a slice, each replaying the rows before its own.
int StepsPerSlice(IN(Item) h, uint slices) { return StepsPerRow(h) * RowsPerSlice(h.n, slices); }

// The second step (StartInput's stack walked): the first hemisphere's cells of this slice's rows
// in `cells`, false where there are none left to trace.
bool InputCells(real3 org, real3 dir, uint slice, uint slices, OUT(Item) cells) {
    if (params.irradiance == 0) return false;
    rng = Key(cell_key, slice, 17u, 5u);
    PushHemisphere(PrimaryRay(org, dir), real3(kPi), InputPoint(org, dir), dir);
    if (top == 0) return false;
    // This slice's share of the rows; the rows before it are replayed without tracing, their
    // steps taken as the cells' first (their directions keep RADIANCE's collision rule), their
    // rays dropped (Replayed).
    Item h = STACK(--top);
    int rows = h.n, per = RowsPerSlice(rows, slices);
    int row_first = int(slice) * per, row_end = min(rows, row_first + per);
    if (row_first >= row_end) return false;
    int row_steps = StepsPerRow(h), replayed = row_first * h.n;
#ifdef DAYFLUX_ASUB
    if (params.asub > 1) {
        // -asub's steps draw from numbers keyed by the step and keep no rows: of the steps
        // before, only step 0's start is replayed
        if (row_first > 0) StartSubsamples();
        replayed = 0;
    }
#endif
    steps_replayed = row_first * row_steps;
    h.next = steps_replayed - replayed;
    h.end = row_end * row_steps;
    cells = h;
    return true;
}

// For a driver that traces several cells' paths at once (the CPU's in packets, the GPU's paths
// engine): the next ray of the first hemisphere `cells` (from InputCells) in r, with the random
// state its path goes on from in state, and whether it is the hemisphere's last; false once no
// cell is left. A cell's path draws only from that state and touches no state of the first
// level, so each may run on a stack of its own (StartCellPath) and give the same numbers as
// `cells` pushed whole.
bool NextCell(INOUT(Item) cells, OUT(Ray) r, OUT(uint) state, OUT(bool) last) {
    top = 0;
    while (cells.next < cells.end) {
        if (!AmbientStep(cells)) continue;
        if (Replayed(cells)) {  // (as NextRay)
            top = 0;
            continue;
        }
        r = STACK(--top).r;
        state = rng;
        last = cells.next >= cells.end;
        return true;
    }
    return false;
}

// Starts cell ray r's path (from NextCell) on this stack, with the room `cells` pushed whole
// leaves it: the hemisphere's item holds the bottom slot under every cell's path but the last
// one's (so a path that fills the stack drops what it drops there); here a spent item holds it,
// which NextRay takes off once the path is done. NextRay and ShadeMet walk it.
void StartCellPath(IN(Ray) r, uint state, bool last) {
    top = 0;
    if (!last) {
        STACK(0).kind = kItemDirect;
        STACK(0).next = 0;
        STACK(0).end = 0;
        top = 1;
    }
    rng = state;
    PushTrace(r);
}
