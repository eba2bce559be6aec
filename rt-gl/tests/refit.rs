//! Buffer draws whose vertices change but whose triangles do not: the
//! new cache entry's BVHs are the previous entry's refitted, and answer
//! every ray as a fresh build would.

extern crate alloc;

use alloc::sync::{Arc, Weak};

use rt_core::{
    Ray, SceneQuery,
    glam::{Vec3, Vec4},
};
use rt_gl::{
    gl,
    record::{Command, Recorded, Recorder, arrays},
};

/// Vertices per side of the test grid.
const N: usize = 9;
/// Buffer ids: positions and indices.
const VBO: u32 = 1;
const EBO: u32 = 2;

fn bytes_f32(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_ne_bytes()).collect()
}

fn bytes_u32(v: &[u32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_ne_bytes()).collect()
}

/// An `N × N` height field over `[−1, 1]²` at phase `phase`: a wave in z.
fn wave(phase: f32) -> Vec<f32> {
    let mut p = Vec::with_capacity(3 * N * N);
    for j in 0..N {
        for i in 0..N {
            let (x, y) =
                (2.0 * i as f32 / (N - 1) as f32 - 1.0, 2.0 * j as f32 / (N - 1) as f32 - 1.0);
            p.extend([x, y, -3.0 + 0.4 * (3.0 * x + phase).sin() * (2.0 * y).cos()]);
        }
    }
    p
}

/// Two triangles per grid cell.
fn grid_indices() -> Vec<u32> {
    let n = N as u32;
    let mut idx = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let (a, b, c, d) = (j * n + i, j * n + i + 1, (j + 1) * n + i, (j + 1) * n + i + 1);
            idx.extend([a, b, d, a, d, c]);
        }
    }
    idx
}

/// A recorder with `positions` in buffer `VBO`, `indices` in `EBO`, the
/// vertex array enabled and the modelview the identity.
fn recorder(positions: &[f32], indices: &[u32]) -> Recorder {
    let mut r = Recorder::new();
    r.bind_buffer(arrays::ARRAY_BUFFER, VBO);
    let p = bytes_f32(positions);
    r.buffer_data(arrays::ARRAY_BUFFER, p.len(), Some(&p));
    r.pointer(arrays::VERTEX_ARRAY, 3, gl::FLOAT, 0, 0);
    r.client_state(arrays::VERTEX_ARRAY, true);
    r.bind_buffer(arrays::ELEMENT_ARRAY_BUFFER, EBO);
    let i = bytes_u32(indices);
    r.buffer_data(arrays::ELEMENT_ARRAY_BUFFER, i.len(), Some(&i));
    r
}

/// `glDrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, 0)` from `EBO`,
/// then the frame's single instance.
fn draw_elements(r: &mut Recorder, count: usize) -> Arc<Recorded> {
    // SAFETY: the arrays and indices live in buffer objects (bounds-checked).
    unsafe { r.draw_elements(gl::TRIANGLES, count as i32, gl::UNSIGNED_INT, 0) };
    let frame = r.end_frame().draws();
    assert_eq!(frame.instances.len(), 1);
    Arc::clone(&frame.instances[0].recorded)
}

/// Replaces the positions in `VBO`.
fn move_vertices(r: &mut Recorder, positions: &[f32]) {
    r.bind_buffer(arrays::ARRAY_BUFFER, VBO);
    r.buffer_sub_data(arrays::ARRAY_BUFFER, 0, &bytes_f32(positions));
}

/// A 24 × 24 grid of rays straight down over the mesh and a little past
/// it, plus as many slanted ones.
fn rays() -> Vec<Ray> {
    let mut out = Vec::new();
    for j in 0..24 {
        for i in 0..24 {
            let (x, y) = (-1.1 + 2.2 * i as f32 / 23.0, -1.1 + 2.2 * j as f32 / 23.0);
            out.push(Ray::new(Vec3::new(x, y, 2.0), Vec3::NEG_Z));
            out.push(Ray::new(Vec3::new(x - 1.0, y + 0.5, 0.0), Vec3::new(0.3, -0.15, -1.0)));
        }
    }
    out
}

/// `rec`'s scene answers every ray exactly as a fresh build of its
/// geometry; returns how many rays hit.
fn assert_same_as_a_build(rec: &Recorded) -> usize {
    let scene = rec.scene().expect("finite geometry");
    let fresh = rec.geometry().build().expect("finite geometry");
    assert_eq!(rt_accel::Object::bounds(scene), rt_accel::Object::bounds(&fresh));
    let mut hits = 0;
    for ray in rays() {
        let (a, b) = (scene.closest_hit(&ray), fresh.closest_hit(&ray));
        assert_eq!(a, b, "{ray:?}");
        assert_eq!(scene.occluded(&ray), fresh.occluded(&ray), "{ray:?}");
        hits += usize::from(a.is_some());
    }
    hits
}

/// A VBO draw traced, its vertices moved by `glBufferSubData` (and then by
/// `glBufferData` with the same size), drawn again: refits, not builds,
/// that answer every ray as a fresh build does (where the previous BVH,
/// with the vertices where they were, does not); the replaced entries are
/// dropped, not kept in a chain.
#[test]
fn moved_vertices_refit_the_previous_bvh() {
    let idx = grid_indices();
    let mut r = recorder(&wave(0.0), &idx);
    let first = draw_elements(&mut r, idx.len());
    let first_scene = first.scene().expect("finite").clone();
    assert!(!first.is_refit());
    assert_eq!((r.counters.draw_builds, r.counters.draw_refits), (1, 0));

    move_vertices(&mut r, &wave(1.3));
    let second = draw_elements(&mut r, idx.len());
    assert_eq!((r.counters.draw_builds, r.counters.draw_refits), (1, 1));
    assert!(second.is_refit() && !second.is_built());
    assert!(assert_same_as_a_build(&second) > 300);
    // The vertices did move: the first BVH answers many rays otherwise.
    let differ = rays()
        .iter()
        .filter(|ray| first_scene.closest_hit(ray) != second.scene().unwrap().closest_hit(ray))
        .count();
    assert!(differ > 300, "only {differ} rays see the move");
    // Nothing keeps the first recording alive now: not the cache (its key
    // is dead), not the second one (its source was taken out at use).
    let first_weak: Weak<Recorded> = Arc::downgrade(&first);
    drop(first);
    assert!(first_weak.upgrade().is_none(), "the replaced entry is still held");

    // A whole new upload of the same size refits too, and so does a
    // refitted entry's successor.
    r.bind_buffer(arrays::ARRAY_BUFFER, VBO);
    let p = bytes_f32(&wave(2.1));
    r.buffer_data(arrays::ARRAY_BUFFER, p.len(), Some(&p));
    let third = draw_elements(&mut r, idx.len());
    assert!(third.is_refit());
    assert!(assert_same_as_a_build(&third) > 300);
    // Unchanged buffers: the cache answers, nothing is refitted.
    let again = draw_elements(&mut r, idx.len());
    assert!(Arc::ptr_eq(&again, &third));
    assert_eq!((r.counters.draw_builds, r.counters.draw_refits, r.counters.draw_reuses), (1, 2, 1));
    let second_weak = Arc::downgrade(&second);
    drop(second);
    assert!(second_weak.upgrade().is_none());
}

/// A draw whose triangles differ from the previous entry's is built:
/// new indices (the element buffer changed), another count, another
/// primitive type, and a vertex that is not finite (left out, so the
/// triangles after it shift) — each a build, never a refit.
#[test]
fn changed_triangles_are_built_not_refit() {
    let idx = grid_indices();
    let mut r = recorder(&wave(0.0), &idx);
    draw_elements(&mut r, idx.len()).scene().expect("finite");
    // One more build, no more refits, and a scene as a build's.
    let check = |r: &Recorder, rec: &Recorded, builds: &mut u64, refits: u64| {
        *builds += 1;
        assert_eq!((r.counters.draw_builds, r.counters.draw_refits), (*builds, refits));
        assert!(!rec.is_refit());
        assert_same_as_a_build(rec);
    };
    let mut builds = 1;

    // The element buffer rewritten: each cell split along the other
    // diagonal, the vertices unchanged.
    let n = N as u32;
    let mut flipped = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let (a, b, c, d) = (j * n + i, j * n + i + 1, (j + 1) * n + i, (j + 1) * n + i + 1);
            flipped.extend([a, b, c, b, d, c]);
        }
    }
    r.bind_buffer(arrays::ELEMENT_ARRAY_BUFFER, EBO);
    r.buffer_sub_data(arrays::ELEMENT_ARRAY_BUFFER, 0, &bytes_u32(&flipped));
    move_vertices(&mut r, &wave(0.5));
    let rec = draw_elements(&mut r, flipped.len());
    check(&r, &rec, &mut builds, 0);

    // Half the triangles, then the vertices moved for the same count: the
    // count is part of the shape, so the half draw refits only from the
    // half draw.
    let rec = draw_elements(&mut r, flipped.len() / 2);
    check(&r, &rec, &mut builds, 0);
    move_vertices(&mut r, &wave(0.9));
    let rec = draw_elements(&mut r, flipped.len() / 2);
    assert_eq!((r.counters.draw_builds, r.counters.draw_refits), (builds, 1));
    assert!(rec.is_refit());
    assert_same_as_a_build(&rec);

    // Another primitive type over the same buffers.
    // SAFETY: buffer data only, bounds-checked.
    unsafe { r.draw_elements(gl::TRIANGLE_STRIP, flipped.len() as i32, gl::UNSIGNED_INT, 0) };
    let rec = Arc::clone(&r.end_frame().draws().instances[0].recorded);
    check(&r, &rec, &mut builds, 1);

    // The full draw again (its vertices moved since it was traced: a
    // refit), then the same shape with vertex 4 NaN: that vertex is
    // dropped, so the triangles after it refer to other vertices.
    let rec = draw_elements(&mut r, flipped.len());
    assert_eq!((r.counters.draw_builds, r.counters.draw_refits), (builds, 2));
    assert_same_as_a_build(&rec);
    let mut p = wave(1.7);
    p[3 * 4] = f32::NAN;
    move_vertices(&mut r, &p);
    let rec = draw_elements(&mut r, flipped.len());
    check(&r, &rec, &mut builds, 2);
    assert!(rec.geometry().triangles.len() < flipped.len() / 3);
}

/// A triangle degenerate when the previous entry was built is left out
/// of its BVH, so once it has an area the draw is built again (a refit
/// would never hit it); a triangle that collapses is refitted and, as in
/// a build, never hit.
#[test]
fn triangles_that_gain_area_are_built() {
    let idx = grid_indices();
    let mut flat_cell = wave(0.0);
    // Vertex 0 onto vertex 1: cell (0, 0)'s first triangle (0, 1, N + 1)
    // collapses to a segment.
    flat_cell[0] = flat_cell[3];
    flat_cell[1] = flat_cell[4];
    flat_cell[2] = flat_cell[5];
    let mut r = recorder(&flat_cell, &idx);
    draw_elements(&mut r, idx.len()).scene().expect("finite");
    // It gets its area back: built.
    move_vertices(&mut r, &wave(0.0));
    let rec = draw_elements(&mut r, idx.len());
    assert_eq!((r.counters.draw_builds, r.counters.draw_refits), (2, 0));
    assert_same_as_a_build(&rec);
    let down = Ray::new(Vec3::new(-0.9, -0.97, 2.0), Vec3::NEG_Z);
    assert_eq!(rec.scene().unwrap().closest_hit(&down).map(|h| h.prim), Some(0));
    // It collapses again: refitted, and the ray through it finds nothing
    // (cell (0, 0)'s other triangle lies on the other side of its diagonal).
    move_vertices(&mut r, &flat_cell);
    let rec = draw_elements(&mut r, idx.len());
    assert_eq!((r.counters.draw_builds, r.counters.draw_refits), (2, 1));
    assert_same_as_a_build(&rec);
    assert_eq!(rec.scene().unwrap().closest_hit(&down), None);
}

/// A previous entry never traced has no BVHs to refit: the next draw is
/// built. One that is itself waiting on a traced entry passes that entry
/// on, so two updates between traces still refit.
#[test]
fn untraced_entries_fall_back_to_a_build_or_pass_their_source_on() {
    let idx = grid_indices();
    let mut r = recorder(&wave(0.0), &idx);
    let untraced = draw_elements(&mut r, idx.len());
    move_vertices(&mut r, &wave(0.4));
    let rec = draw_elements(&mut r, idx.len());
    assert!(!untraced.is_built());
    assert_eq!((r.counters.draw_builds, r.counters.draw_refits), (2, 0));
    assert!(!rec.is_refit());
    assert_same_as_a_build(&rec);
    drop(untraced);

    // `rec` is traced; two updates follow before the next trace.
    move_vertices(&mut r, &wave(0.8));
    let waiting = draw_elements(&mut r, idx.len());
    move_vertices(&mut r, &wave(1.2));
    let last = draw_elements(&mut r, idx.len());
    assert!(waiting.is_refit() && last.is_refit());
    assert_eq!((r.counters.draw_builds, r.counters.draw_refits), (2, 2));
    assert_same_as_a_build(&last);
    assert_same_as_a_build(&waiting);
    // Both have taken their source out: `rec` is held by nothing else.
    let weak = Arc::downgrade(&rec);
    drop(rec);
    assert!(weak.upgrade().is_none());
}

/// The inherited state is not part of the BVH: the same buffers drawn in
/// another colour record a new entry whose BVHs are refitted, and the
/// geometry carries the new colour.
#[test]
fn a_new_colour_over_the_same_buffers_refits() {
    let idx = grid_indices();
    let mut r = recorder(&wave(0.0), &idx);
    let red = Vec4::new(1.0, 0.0, 0.0, 1.0);
    r.command(Command::Color(red));
    draw_elements(&mut r, idx.len()).scene().expect("finite");
    let blue = Vec4::new(0.0, 0.0, 1.0, 1.0);
    r.command(Command::Color(blue));
    let rec = draw_elements(&mut r, idx.len());
    assert_eq!((r.counters.draw_builds, r.counters.draw_refits), (1, 1));
    assert!(rec.geometry().colors.iter().all(|&c| c == blue));
    assert_same_as_a_build(&rec);
}
