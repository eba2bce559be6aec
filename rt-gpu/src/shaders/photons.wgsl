// Photons through a gridded refractive index: the ray equation
// dx/dt = T, dT/dt = n∇n integrated by kick–drift–kick leapfrog, one
// invocation a photon. Coordinates are relative to the box's lower corner
// (the host subtracts it in f64), and the deflection ΔT = T − n₀·d is
// accumulated apart from T's large constant part n₀·d: in f32, adding
// kicks of ~1e-5 to a T of ~1 would round away a tenth of a weak
// deflection over a hundred steps, kept apart they keep all their bits.

struct Params {
    dims: vec4<u32>,        // samples per axis; w unused
    first: vec4<f32>,       // the first sample's centre; w: step h (in t)
    inv_spacing: vec4<f32>, // 1 / spacing; w unused
    hi: vec4<f32>,          // the box's upper corner (lower is 0); w unused
    counts: vec4<u32>,      // x: photons; y: the most steps a photon takes
};

struct Photon {
    origin: vec4<f32>,    // xyz; w unused
    direction: vec4<f32>, // xyz (unit); w unused
};

struct Exit {
    position: vec4<f32>,   // xyz; w: the optical path beyond the straight line (below)
    deflection: vec4<f32>, // xyz: T − n₀·d at the exit; w: n₀ − 1
    status: vec4<u32>,     // x: 0 missed the box, 1 left it, 2 out of steps; y: steps;
                           // z: the distance to the entry point (f32 bits)
};

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> samples: array<f32>;
@group(0) @binding(2) var<storage, read> photons: array<Photon>;
@group(0) @binding(3) var<storage, read_write> exits: array<Exit>;

fn at(i: u32, j: u32, k: u32) -> f32 {
    return samples[i + params.dims.x * (j + params.dims.y * k)];
}

// n − 1 and ∇n of the trilinear interpolant at x; within half a cell of
// a face (beyond the outer samples) the edge samples, with zero slope
// across that axis. The excess n − 1 keeps the bits that n ≈ 1 would
// round away (`r − 1` is exact in f32 for 0.5 ≤ r ≤ 2).
fn sample(x: vec3<f32>) -> vec4<f32> {
    let u = (x - params.first.xyz) * params.inv_spacing.xyz;
    var b: vec3<u32>;
    var b1: vec3<u32>;
    var f: vec3<f32>;
    var slope = vec3<f32>(1.0);
    for (var a = 0u; a < 3u; a++) {
        let last = params.dims[a] - 1u;
        let hi = f32(last);
        if (u[a] < 0.0 || u[a] > hi) {
            slope[a] = 0.0;
        }
        let ua = clamp(u[a], 0.0, hi);
        var ba = u32(floor(ua));
        if (ba == last && last > 0u) {
            ba = last - 1u;
        }
        b[a] = ba;
        b1[a] = min(ba + 1u, last);
        f[a] = ua - f32(ba);
    }
    // Relative to one corner: the differences of nearby samples are exact
    // in f32, so a weak field (n − 1 ~ 1e-6) keeps its bits through the
    // interpolation, which on the samples themselves would round them to
    // a tenth of their size.
    let r = at(b.x, b.y, b.z);
    let c000 = 0.0;
    let c100 = at(b1.x, b.y, b.z) - r;
    let c010 = at(b.x, b1.y, b.z) - r;
    let c110 = at(b1.x, b1.y, b.z) - r;
    let c001 = at(b.x, b.y, b1.z) - r;
    let c101 = at(b1.x, b.y, b1.z) - r;
    let c011 = at(b.x, b1.y, b1.z) - r;
    let c111 = at(b1.x, b1.y, b1.z) - r;
    let e00 = mix(c000, c100, f.x);
    let e10 = mix(c010, c110, f.x);
    let e01 = mix(c001, c101, f.x);
    let e11 = mix(c011, c111, f.x);
    let f0 = mix(e00, e10, f.y);
    let f1 = mix(e01, e11, f.y);
    let v = (r - 1.0) + mix(f0, f1, f.z);
    let gx = mix(mix(c100 - c000, c110 - c010, f.y), mix(c101 - c001, c111 - c011, f.y), f.z);
    let gy = mix(e10 - e00, e11 - e01, f.z);
    let gz = f1 - f0;
    return vec4<f32>(v, vec3<f32>(gx, gy, gz) * params.inv_spacing.xyz * slope);
}

fn inside(x: vec3<f32>) -> bool {
    return all(x >= vec3<f32>(0.0)) && all(x <= params.hi.xyz);
}

// The parameter where the line x + s·v leaves the box (x inside).
fn leave(x: vec3<f32>, v: vec3<f32>) -> f32 {
    var s = 3.0e38;
    for (var a = 0u; a < 3u; a++) {
        if (v[a] > 0.0) {
            s = min(s, (params.hi[a] - x[a]) / v[a]);
        } else if (v[a] < 0.0) {
            s = min(s, -x[a] / v[a]);
        }
    }
    return max(s, 0.0);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let p = id.x;
    if (p >= params.counts.x) {
        return;
    }
    let o = photons[p].origin.xyz;
    let d = photons[p].direction.xyz;
    var out: Exit;
    // Entry: the slab test against [0, hi] (an axis the ray runs along
    // only checks that the origin lies within its slab).
    var near = 0.0;
    var far = 3.0e38;
    for (var a = 0u; a < 3u; a++) {
        if (d[a] == 0.0) {
            if (o[a] < 0.0 || o[a] > params.hi[a]) {
                far = -1.0;
            }
        } else {
            let ta = (0.0 - o[a]) / d[a];
            let tb = (params.hi[a] - o[a]) / d[a];
            near = max(near, min(ta, tb));
            far = min(far, max(ta, tb));
        }
    }
    if (!(near <= far)) {
        out.position = vec4<f32>(o, 0.0);
        out.deflection = vec4<f32>(0.0);
        out.status = vec4<u32>(0u);
        exits[p] = out;
        return;
    }
    var x = clamp(o + near * d, vec3<f32>(0.0), params.hi.xyz);
    var s = sample(x);
    let e0 = s.x;
    let base = (1.0 + e0) * d;
    var dt = vec3<f32>(0.0);
    // The optical path beyond (x_exit − x_entry)·d, the straight line's:
    // per step (n̄ − 1)·|Δx| and the step's excess length over its
    // projection on d, |Δx × d|² / (|Δx| + Δx·d), both small, so f32 keeps
    // their bits (a sum of n̄·|Δx| would round at the ulp of the whole
    // path, 0.1 rad of phase at λ = 500 nm).
    var bend = 0.0;
    let h = params.first.w;
    let max_steps = params.counts.y;
    var status = 2u;
    var steps = 0u;
    loop {
        if (steps >= max_steps) {
            break;
        }
        // Kick, drift, kick; the next step's first kick reuses `s`.
        let half = dt + 0.5 * h * (1.0 + s.x) * s.yzw;
        var xn = x + h * (base + half);
        var sn = sample(xn);
        var hn = h;
        var left = false;
        if (!inside(xn)) {
            // The same step shortened to land on the face the chord
            // leaves by, then snapped onto it.
            hn = h * min(leave(x, xn - x), 1.0);
            let half_n = dt + 0.5 * hn * (1.0 + s.x) * s.yzw;
            xn = clamp(x + hn * (base + half_n), vec3<f32>(0.0), params.hi.xyz);
            sn = sample(xn);
            left = true;
        }
        let half2 = dt + 0.5 * hn * (1.0 + s.x) * s.yzw;
        dt = half2 + 0.5 * hn * (1.0 + sn.x) * sn.yzw;
        let dx = xn - x;
        let len = length(dx);
        let side = cross(dx, d);
        let along = dot(dx, d);
        var extra = 0.0;
        if (len + along > 0.0) {
            extra = dot(side, side) / (len + along);
        }
        bend += 0.5 * (s.x + sn.x) * len + extra;
        x = xn;
        s = sn;
        steps++;
        if (left) {
            status = 1u;
            break;
        }
    }
    out.position = vec4<f32>(x, bend);
    out.deflection = vec4<f32>(dt, e0);
    out.status = vec4<u32>(status, steps, bitcast<u32>(near), 0u);
    exits[p] = out;
}
