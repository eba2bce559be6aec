//! Malformed byte blobs: every way a serialized BVH can be cut short,
//! corrupted or mislabelled is an `Err` naming the cause, from both the
//! copying loader (`Bvh::from_bytes`) and the zero-copy one
//! (`BvhRef::from_bytes`), never a panic; blobs that still load traverse
//! without panicking. Layout sizes come from the public types, so the tests
//! follow the format if the node layout changes.

mod support;

use std::sync::LazyLock;

use proptest::prelude::*;
use rt_accel::{
    BuildParams, Bvh, BvhRef, CapsuleItem, ChildRef, Header, LoadError, MAGIC, MAX_DEPTH,
    MAX_ITEMS, MAX_NODES, NODE_BYTES, Node, Primitive, SphereItem, TraversalStats, TriPacket,
    VERSION, WIDTH, build_capsules, build_spheres, build_triangles,
};
use rt_core::{
    Aabb, Ray,
    glam::Vec3,
    intersect::{Capsule, Sphere},
};
use support::*;

const HEADER: usize = size_of::<Header>();
const NODE: usize = size_of::<Node>();

/// A 64-byte line: storage aligned for zero-copy loading.
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(64))]
struct Line([u8; 64]);

/// Runs `f` on a copy of `bytes` that starts `offset` bytes after a 64-byte
/// boundary.
fn with_aligned<R>(bytes: &[u8], offset: usize, f: impl FnOnce(&[u8]) -> R) -> R {
    let mut lines = vec![Line([0; 64]); (offset + bytes.len()).div_ceil(64)];
    let store = bytemuck::cast_slice_mut::<Line, u8>(&mut lines);
    store[offset..offset + bytes.len()].copy_from_slice(bytes);
    f(&store[offset..offset + bytes.len()])
}

/// Loads `bytes` with both loaders, asserts that they agree (same arrays,
/// or the same error), and returns the copying loader's answer.
fn load<P: Primitive>(bytes: &[u8]) -> Result<Bvh<P>, LoadError> {
    let copied = Bvh::<P>::from_bytes(bytes);
    with_aligned(bytes, 0, |b| match (&copied, BvhRef::<P>::from_bytes(b)) {
        (Ok(c), Ok(v)) => {
            let c = c.as_ref();
            assert_eq!(
                bytemuck::cast_slice::<Node, u8>(v.nodes()),
                bytemuck::cast_slice(c.nodes())
            );
            assert_eq!(bytemuck::cast_slice::<P, u8>(v.items()), bytemuck::cast_slice(c.items()));
            assert_eq!(v.prim_count(), c.prim_count());
        }
        (Err(a), Err(b)) => assert_eq!(*a, b, "the loaders disagree"),
        (c, v) => panic!("one loader accepted: copy {:?}, view {:?}", c.as_ref().err(), v.err()),
    });
    copied
}

/// The error of loading `bytes` as `P` (both loaders agreeing).
fn load_err<P: Primitive>(bytes: &[u8]) -> LoadError {
    load::<P>(bytes).err().expect("malformed bytes loaded")
}

fn header(bytes: &[u8]) -> Header {
    bytemuck::pod_read_unaligned(&bytes[..HEADER])
}

fn nodes_of(bytes: &[u8]) -> Vec<Node> {
    let n = header(bytes).node_count as usize;
    bytemuck::pod_collect_to_vec(&bytes[HEADER..HEADER + n * NODE])
}

fn items_of<P: Primitive>(bytes: &[u8]) -> Vec<P> {
    let n = header(bytes).node_count as usize;
    bytemuck::pod_collect_to_vec(&bytes[HEADER + n * NODE..])
}

/// A blob of `h` (counts set from the arrays), `nodes` and `items`.
fn assemble<P: Primitive>(h: Header, nodes: &[Node], items: &[P]) -> Vec<u8> {
    let h = Header { node_count: nodes.len() as u32, item_count: items.len() as u32, ..h };
    let mut out = bytemuck::bytes_of(&h).to_vec();
    out.extend_from_slice(bytemuck::cast_slice(nodes));
    out.extend_from_slice(bytemuck::cast_slice(items));
    out
}

/// `bytes` with the header edited by `f` (nothing else changed).
fn edit_header(bytes: &[u8], f: impl FnOnce(&mut Header)) -> Vec<u8> {
    let mut h = header(bytes);
    f(&mut h);
    let mut out = bytes.to_vec();
    out[..HEADER].copy_from_slice(bytemuck::bytes_of(&h));
    out
}

/// `bytes` with the nodes edited by `f`.
fn edit_nodes<P: Primitive>(bytes: &[u8], f: impl FnOnce(&mut Vec<Node>)) -> Vec<u8> {
    let mut nodes = nodes_of(bytes);
    f(&mut nodes);
    assemble::<P>(header(bytes), &nodes, &items_of::<P>(bytes))
}

/// `bytes` with the items edited by `f`.
fn edit_items<P: Primitive>(bytes: &[u8], f: impl FnOnce(&mut Vec<P>)) -> Vec<u8> {
    let mut items = items_of::<P>(bytes);
    f(&mut items);
    assemble(header(bytes), &nodes_of(bytes), &items)
}

/// A triangle BVH of several levels with partly filled packets.
fn tri_bvh() -> TriBvh {
    let (pos, idx) = icosphere(3);
    build_triangles(&pos, &idx, &params()).unwrap()
}

fn sphere_bvh() -> SphereBvh {
    let s: Vec<Sphere> = (0..40)
        .map(|i| Sphere::new(Vec3::new(i as f32, (i % 7) as f32, (i % 3) as f32), 0.4))
        .collect();
    build_spheres(&s, &params()).unwrap()
}

fn capsule_bvh() -> CapsuleBvh {
    let c: Vec<Capsule> = (0..40)
        .map(|i| {
            let p = Vec3::new(i as f32, (i % 5) as f32, 0.0);
            Capsule::new(p, p + Vec3::new(0.5, 0.25, 1.0), 0.2)
        })
        .collect();
    build_capsules(&c, &params()).unwrap()
}

/// Rays through and around the unit sphere, with finite and infinite ranges.
fn probe_rays() -> Vec<Ray> {
    let mut rays = Vec::new();
    for (i, d) in [Vec3::NEG_Z, Vec3::X, Vec3::new(0.3, -0.7, 0.2), Vec3::new(-1.0, -0.0, 0.5)]
        .into_iter()
        .enumerate()
    {
        let o = -d.normalize() * 3.0 + Vec3::new(0.1 * i as f32, 0.05, -0.02);
        rays.push(Ray::with_range(o, d, 0.0, 100.0));
        rays.push(Ray::new(o, d));
        rays.push(Ray::new(Vec3::new(0.05, 0.1, -0.15), d));
    }
    rays
}

/// A serialized BVH of each kind loads back bit for bit through both
/// loaders, with the documented layout: a 64-byte header holding the magic,
/// version, kind tag and counts, then the nodes, then the items. (The
/// baseline every corruption below starts from.)
#[test]
fn valid_blobs_round_trip_through_both_loaders() {
    assert_eq!(HEADER, 64);
    let bvh = tri_bvh();
    let bytes = bvh.to_bytes();
    let h = header(&bytes);
    assert_eq!((h.magic, h.version, h.tag), (MAGIC, VERSION, TriPacket::TAG));
    assert_eq!(h.node_count as usize, bvh.node_count());
    assert_eq!(h.item_count as usize, bvh.items().len());
    assert_eq!(h.prim_count, bvh.prim_count());
    assert_eq!(h.reserved, [0; 8]);
    assert_eq!(bytes.len(), HEADER + bvh.node_count() * NODE + size_of_val(bvh.items()));
    assert!(bvh.node_count() > 8 && bvh.depth() > 2, "a tree with inner levels");
    assert_eq!(load::<TriPacket>(&bytes).unwrap(), bvh);
    let s = sphere_bvh();
    assert_eq!(load::<SphereItem>(&s.to_bytes()).unwrap(), s);
    let c = capsule_bvh();
    assert_eq!(load::<CapsuleItem>(&c.to_bytes()).unwrap(), c);
    let empty = Bvh::<TriPacket>::empty();
    assert_eq!(load::<TriPacket>(&empty.to_bytes()).unwrap(), empty);
}

/// Truncation check for one blob: every proper prefix, and the blob with
/// bytes appended, is `BadLength` from both loaders.
fn assert_truncations_rejected<P: Primitive>(bytes: &[u8]) {
    with_aligned(bytes, 0, |aligned| {
        for len in 0..bytes.len() {
            assert_eq!(
                Bvh::<P>::from_bytes(&bytes[..len]).err(),
                Some(LoadError::BadLength),
                "len {len}"
            );
            assert_eq!(
                BvhRef::<P>::from_bytes(&aligned[..len]).err(),
                Some(LoadError::BadLength),
                "len {len}"
            );
        }
    });
    for extra in [1, 15, NODE] {
        let mut longer = bytes.to_vec();
        longer.resize(bytes.len() + extra, 0);
        assert_eq!(load_err::<P>(&longer), LoadError::BadLength);
    }
}

/// Every truncation of a valid blob (lengths 0 … len − 1), and the blob
/// with bytes appended, is `LoadError::BadLength` for triangles, spheres,
/// capsules and the empty BVH.
#[test]
fn every_truncation_is_bad_length() {
    assert_truncations_rejected::<TriPacket>(&tri_bvh().to_bytes());
    assert_truncations_rejected::<SphereItem>(&sphere_bvh().to_bytes());
    assert_truncations_rejected::<CapsuleItem>(&capsule_bvh().to_bytes());
    assert_truncations_rejected::<TriPacket>(&Bvh::<TriPacket>::empty().to_bytes());
}

/// Changing any magic byte gives `BadMagic`, as do 64 zero bytes.
#[test]
fn bad_magic_is_rejected() {
    let bytes = tri_bvh().to_bytes();
    for i in 0..MAGIC.len() {
        for x in [0x01, 0x80, 0xff] {
            let mut bad = bytes.clone();
            bad[i] ^= x;
            assert_eq!(load_err::<TriPacket>(&bad), LoadError::BadMagic, "byte {i} ^ {x:#x}");
        }
    }
    assert_eq!(load_err::<TriPacket>(&[0; HEADER]), LoadError::BadMagic);
}

/// A version other than [`VERSION`] is `UnsupportedVersion` carrying the
/// version found.
#[test]
fn other_versions_are_rejected() {
    let bytes = tri_bvh().to_bytes();
    for v in [0, VERSION + 1, VERSION.wrapping_sub(1), u32::MAX] {
        if v == VERSION {
            continue;
        }
        let bad = edit_header(&bytes, |h| h.version = v);
        assert_eq!(load_err::<TriPacket>(&bad), LoadError::UnsupportedVersion(v));
    }
}

/// A blob of one primitive kind loaded as another (triangles as spheres or
/// capsules and so on), or with an unknown tag, is `WrongKind` naming the
/// expected and the found tag.
#[test]
fn wrong_kind_is_rejected() {
    let (t, s, c) = (tri_bvh().to_bytes(), sphere_bvh().to_bytes(), capsule_bvh().to_bytes());
    let wrong = |expected, found| LoadError::WrongKind { expected, found };
    assert_eq!(load_err::<SphereItem>(&t), wrong(SphereItem::TAG, TriPacket::TAG));
    assert_eq!(load_err::<CapsuleItem>(&t), wrong(CapsuleItem::TAG, TriPacket::TAG));
    assert_eq!(load_err::<TriPacket>(&s), wrong(TriPacket::TAG, SphereItem::TAG));
    assert_eq!(load_err::<CapsuleItem>(&s), wrong(CapsuleItem::TAG, SphereItem::TAG));
    assert_eq!(load_err::<TriPacket>(&c), wrong(TriPacket::TAG, CapsuleItem::TAG));
    assert_eq!(load_err::<SphereItem>(&c), wrong(SphereItem::TAG, CapsuleItem::TAG));
    for tag in [0, 99, u32::MAX] {
        let bad = edit_header(&t, |h| h.tag = tag);
        assert_eq!(load_err::<TriPacket>(&bad), wrong(TriPacket::TAG, tag));
    }
    // Distinct tags, or the check above could not tell the kinds apart.
    const {
        assert!(
            TriPacket::TAG != SphereItem::TAG
                && SphereItem::TAG != CapsuleItem::TAG
                && CapsuleItem::TAG != TriPacket::TAG
        );
    }
}

/// A byte-swapped endianness marker is `WrongEndianness`, also when the
/// whole header is byte-swapped as a writer of the other byte order would
/// produce it (the marker is checked before the then-swapped version).
#[test]
fn other_byte_order_is_rejected() {
    let bytes = tri_bvh().to_bytes();
    let bad = edit_header(&bytes, |h| h.endian = h.endian.swap_bytes());
    assert_eq!(load_err::<TriPacket>(&bad), LoadError::WrongEndianness);
    let swapped = edit_header(&bytes, |h| {
        for f in [
            &mut h.version,
            &mut h.endian,
            &mut h.tag,
            &mut h.node_count,
            &mut h.item_count,
            &mut h.prim_count,
        ] {
            *f = f.swap_bytes();
        }
    });
    assert_eq!(load_err::<TriPacket>(&swapped), LoadError::WrongEndianness);
}

/// `(node, slot)` of every inner (`inner = true`) or leaf child reference.
fn child_slots(nodes: &[Node], inner: bool) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for (i, n) in nodes.iter().enumerate() {
        for (s, c) in n.children.iter().enumerate() {
            if !c.is_empty() && c.is_leaf() != inner {
                out.push((i, s));
            }
        }
    }
    out
}

/// For every inner child reference in the tree: pointing it at its own
/// node, back at the root or the node before, just past the end or at the
/// largest index is `BadChild` naming that node.
#[test]
fn child_refs_backwards_or_past_the_end_are_rejected() {
    let bytes = tri_bvh().to_bytes();
    let nodes = nodes_of(&bytes);
    let n = nodes.len() as u32;
    let slots = child_slots(&nodes, true);
    assert_eq!(slots.len(), nodes.len() - 1, "every node but the root has one parent");
    for (i, s) in slots {
        let iu = i as u32;
        for target in [iu, 0, iu.saturating_sub(1), n, n + 1000, MAX_NODES - 1] {
            let bad = edit_nodes::<TriPacket>(&bytes, |nodes| {
                nodes[i].children[s] = ChildRef::inner(target)
            });
            assert_eq!(
                load_err::<TriPacket>(&bad),
                LoadError::BadChild { node: i },
                "node {i} slot {s} → {target}"
            );
        }
    }
}

/// Inner references are byte offsets (format version 2): every offset
/// between two nodes, even one inside the right node, is `BadChild`
/// naming the node that holds it (its index would floor to a valid one).
#[test]
fn child_offsets_between_nodes_are_rejected() {
    let bytes = tri_bvh().to_bytes();
    let nodes = nodes_of(&bytes);
    for (i, s) in child_slots(&nodes, true) {
        let good = nodes[i].children[s];
        assert_eq!(good.byte_offset(), good.index() * NODE_BYTES as usize);
        for k in [1, 4, 16, 32, NODE_BYTES - 1] {
            let bad = edit_nodes::<TriPacket>(&bytes, |nodes| {
                nodes[i].children[s] = ChildRef(good.0 + k);
            });
            assert_eq!(
                load_err::<TriPacket>(&bad),
                LoadError::BadChild { node: i },
                "{i} {s} +{k}"
            );
        }
    }
}

/// For every leaf reference: a range starting at the item count, one
/// running one item past the end, a full leaf of 16 past the end, or the
/// largest first index is `LeafOutOfRange` naming the node; a range ending
/// exactly at the last item is accepted.
#[test]
fn leaf_ranges_past_the_items_are_rejected() {
    let bytes = tri_bvh().to_bytes();
    let nodes = nodes_of(&bytes);
    let items = header(&bytes).item_count;
    assert!(items > 16);
    let slots = child_slots(&nodes, false);
    assert!(slots.len() > 10);
    for &(i, s) in &slots {
        for (first, count) in [(items, 1), (items - 1, 2), (items - 15, 16), (MAX_ITEMS - 1, 16)] {
            let bad = edit_nodes::<TriPacket>(&bytes, |nodes| {
                nodes[i].children[s] = ChildRef::leaf(first, count)
            });
            assert_eq!(
                load_err::<TriPacket>(&bad),
                LoadError::LeafOutOfRange { node: i },
                "node {i} slot {s} → ({first}, {count})"
            );
        }
    }
    // The boundary: the last item alone, or the last 16, is a valid range.
    let (i, s) = slots[0];
    for (first, count) in [(items - 1, 1), (items - 16, 16)] {
        let ok = edit_nodes::<TriPacket>(&bytes, |nodes| {
            nodes[i].children[s] = ChildRef::leaf(first, count)
        });
        assert!(load::<TriPacket>(&ok).is_ok(), "({first}, {count})");
    }
}

/// A NaN or ±∞ in any coordinate of a used packet lane (first, middle and
/// last packet; first and last used lane) is `BadItem` naming the packet,
/// while the NaN filling unused lanes is what valid blobs hold.
#[test]
fn non_finite_vertices_in_used_lanes_are_rejected() {
    let bvh = tri_bvh();
    let bytes = bvh.to_bytes();
    let items = bvh.items();
    let partial = items.iter().position(|p| p.len() < 4).expect("a partly filled packet");
    assert!(
        items[partial]
            .v
            .iter()
            .flatten()
            .flat_map(|a| &a[items[partial].len()..])
            .all(|x| x.is_nan())
    );
    for item in [0, items.len() / 2, partial, items.len() - 1] {
        for lane in [0, items[item].len() - 1] {
            for k in 0..3 {
                for a in 0..3 {
                    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
                        let blob =
                            edit_items::<TriPacket>(&bytes, |it| it[item].v[k][a][lane] = bad);
                        assert_eq!(
                            load_err::<TriPacket>(&blob),
                            LoadError::BadItem { item },
                            "item {item} lane {lane} v{k}[{a}] = {bad}"
                        );
                    }
                }
            }
        }
    }
}

/// Primitive ids must be below `prim_count`: an id equal to it, a header
/// count lowered below the largest id, a count of zero, and a used lane
/// after an unused one (`u32::MAX`, lanes fill from lane 0) are `BadItem`
/// naming the first offending item; the same for sphere and capsule items,
/// which are also rejected for invalid radii or non-finite points.
#[test]
fn bad_prim_ids_and_primitives_are_rejected() {
    let bvh = tri_bvh();
    let bytes = bvh.to_bytes();
    let n = bvh.prim_count();
    let bad = edit_items::<TriPacket>(&bytes, |it| it[3].prims[0] = n);
    assert_eq!(load_err::<TriPacket>(&bad), LoadError::BadItem { item: 3 });
    let bad = edit_items::<TriPacket>(&bytes, |it| it[3].prims[0] = u32::MAX - 1);
    assert_eq!(load_err::<TriPacket>(&bad), LoadError::BadItem { item: 3 });
    // Lane 0 unused but lane 1 used.
    let two = bvh.items().iter().position(|p| p.len() >= 2).unwrap();
    let bad = edit_items::<TriPacket>(&bytes, |it| it[two].prims[0] = u32::MAX);
    assert_eq!(load_err::<TriPacket>(&bad), LoadError::BadItem { item: two });
    // A header count that no longer covers the largest id.
    let first_with_max =
        bvh.items().iter().position(|p| p.prims[..p.len()].contains(&(n - 1))).unwrap();
    let bad = edit_header(&bytes, |h| h.prim_count = n - 1);
    assert_eq!(load_err::<TriPacket>(&bad), LoadError::BadItem { item: first_with_max });
    let bad = edit_header(&bytes, |h| h.prim_count = 0);
    assert_eq!(load_err::<TriPacket>(&bad), LoadError::BadItem { item: 0 });

    let s = sphere_bvh().to_bytes();
    let sn = header(&s).prim_count;
    let edits: [fn(&mut SphereItem, u32); 6] = [
        |it, n| it.prim = n,
        |it, _| it.sphere.radius = 0.0,
        |it, _| it.sphere.radius = -1.0,
        |it, _| it.sphere.radius = f32::NAN,
        |it, _| it.sphere.radius = f32::INFINITY,
        |it, _| it.sphere.center.y = f32::NAN,
    ];
    for e in edits {
        let bad = edit_items::<SphereItem>(&s, |it| e(&mut it[5], sn));
        assert_eq!(load_err::<SphereItem>(&bad), LoadError::BadItem { item: 5 });
    }
    let c = capsule_bvh().to_bytes();
    let cn = header(&c).prim_count;
    let edits: [fn(&mut CapsuleItem, u32); 4] = [
        |it, n| it.prim = n,
        |it, _| it.capsule.radius = 0.0,
        |it, _| it.capsule.p1.z = f32::NEG_INFINITY,
        |it, _| it.capsule.p0.x = f32::NAN,
    ];
    for e in edits {
        let bad = edit_items::<CapsuleItem>(&c, |it| e(&mut it[7], cn));
        assert_eq!(load_err::<CapsuleItem>(&bad), LoadError::BadItem { item: 7 });
    }
}

/// Headers claiming `u32::MAX` nodes and/or items (sizes of hundreds of
/// GiB, products that overflow 32-bit sizes) are `BadLength`, checked
/// before anything is allocated or read, for every kind.
#[test]
fn huge_counts_are_rejected_without_overflow() {
    fn check<P: Primitive>(bytes: &[u8]) {
        let h = header(bytes);
        for (nodes, items) in [
            (u32::MAX, h.item_count),
            (h.node_count, u32::MAX),
            (u32::MAX, u32::MAX),
            (u32::MAX, 0),
            (0, u32::MAX),
            (u32::MAX / NODE as u32 + 1, 0),
            (0, u32::MAX / size_of::<P>() as u32 + 1),
        ] {
            let bad = edit_header(bytes, |h| (h.node_count, h.item_count) = (nodes, items));
            assert_eq!(load_err::<P>(&bad), LoadError::BadLength, "{nodes} nodes, {items} items");
        }
    }
    check::<TriPacket>(&tri_bvh().to_bytes());
    check::<SphereItem>(&sphere_bvh().to_bytes());
    check::<CapsuleItem>(&capsule_bvh().to_bytes());
}

/// An empty slot whose box a ray could enter is `OpenEmptySlot` naming the
/// node, whatever the box (the whole scene's, a flat one, or a box with one
/// empty axis only); the traversal never checks slots for emptiness, so
/// such a blob must not load.
#[test]
fn empty_slots_with_boxes_are_rejected() {
    let bytes = tri_bvh().to_bytes();
    let nodes = nodes_of(&bytes);
    let (i, s) = (0..nodes.len())
        .flat_map(|i| (0..WIDTH).map(move |s| (i, s)))
        .find(|&(i, s)| nodes[i].children[s].is_empty())
        .expect("a node with an empty slot");
    let scene = nodes[0].bounds();
    let flat = Aabb::new(scene.min, Vec3::new(scene.max.x, scene.min.y, scene.max.z));
    let one_axis =
        Aabb::new(Vec3::new(0.0, f32::INFINITY, 0.0), Vec3::new(1.0, f32::NEG_INFINITY, 1.0));
    for b in [scene, flat, one_axis] {
        let bad = edit_nodes::<TriPacket>(&bytes, |nodes| nodes[i].set_child_bounds(s, b));
        assert_eq!(load_err::<TriPacket>(&bad), LoadError::OpenEmptySlot { node: i }, "{b:?}");
    }
    // Every empty slot the builder writes holds the empty box.
    assert!(load::<TriPacket>(&bytes).is_ok());
}

/// Nodes that cannot be reached from the root, and items without any node,
/// are `NotATree`.
#[test]
fn unreachable_nodes_are_not_a_tree() {
    let bytes = tri_bvh().to_bytes();
    // An extra copy of the last node, referenced by no one.
    let bad = edit_nodes::<TriPacket>(&bytes, |nodes| nodes.push(*nodes.last().unwrap()));
    assert_eq!(load_err::<TriPacket>(&bad), LoadError::NotATree);
    // Items but no nodes.
    let bad = edit_nodes::<TriPacket>(&bytes, Vec::clear);
    assert_eq!(load_err::<TriPacket>(&bad), LoadError::NotATree);
}

/// Size of the subtree under node `i`.
fn subtree_size(nodes: &[Node], i: usize) -> usize {
    1 + nodes[i]
        .children
        .iter()
        .filter(|c| !c.is_leaf())
        .map(|c| subtree_size(nodes, c.index()))
        .sum::<usize>()
}

/// A node reached twice (one child reference redirected to its sibling, so
/// the sibling's subtree is shared and the old child's is unreachable) is
/// not a tree and must be `NotATree`, even when the two subtrees have the
/// same size (so one node visited twice plus one never visited would add up
/// to the node count: counting visits is not enough).
#[test]
fn nodes_reached_twice_are_not_a_tree() {
    let bytes = tri_bvh().to_bytes();
    let nodes = nodes_of(&bytes);
    let (i, a, b) = (0..nodes.len())
        .flat_map(|i| (0..WIDTH).flat_map(move |a| (0..WIDTH).map(move |b| (i, a, b))))
        .find(|&(i, a, b)| {
            let (ca, cb) = (nodes[i].children[a], nodes[i].children[b]);
            a != b
                && !ca.is_leaf()
                && !cb.is_leaf()
                && subtree_size(&nodes, ca.index()) == subtree_size(&nodes, cb.index())
        })
        .expect("two sibling subtrees of equal size");
    let bad = edit_nodes::<TriPacket>(&bytes, |nodes| nodes[i].children[a] = nodes[i].children[b]);
    assert_eq!(load::<TriPacket>(&bad).err(), Some(LoadError::NotATree));
}

/// A chain of `depth` nodes whose child boxes all hold `[-10, 10]³`: all
/// slots but the last are leaves of the one item, the last slot the next
/// node (the last node has only leaves). The worst case for the fixed
/// traversal stacks: every level pushes `WIDTH − 1` siblings.
fn chain(depth: usize) -> Vec<u8> {
    // The node layout is the crate's own: take a real node whose child
    // boxes all hold the cube, and rewire its children.
    let s = [Sphere::new(Vec3::ZERO, 10.0); WIDTH];
    let one_per_leaf = BuildParams { max_leaf_size: 1, ..params() };
    let boxes = build_spheres(&s, &one_per_leaf).unwrap();
    let template = boxes.as_ref().nodes()[0];
    assert_eq!(boxes.node_count(), 1);
    assert!(template.children.iter().all(|c| c.is_leaf() && !c.is_empty()));
    let nodes: Vec<Node> = (0..depth)
        .map(|i| {
            let mut n = template;
            let leaf = ChildRef::leaf(0, 1);
            n.children = [leaf; WIDTH];
            if i + 1 < depth {
                n.children[WIDTH - 1] = ChildRef::inner(i as u32 + 1);
            }
            n
        })
        .collect();
    let mut packet = TriPacket::EMPTY;
    packet.set_lane(
        0,
        0,
        [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
    );
    let h = Header { prim_count: 1, ..header(&tri_bvh().to_bytes()) };
    assemble(h, &nodes, &[packet])
}

/// The deepest tree the loaders accept ([`MAX_DEPTH`] levels, `WIDTH − 1`
/// siblings pushed per level) is traversed within the fixed stacks: a ray
/// that enters every box but misses the triangle visits every node and
/// every leaf (no overflow, nothing skipped), a ray through the triangle
/// finds it; one level more is `TooDeep`.
#[test]
fn deepest_accepted_tree_fits_the_traversal_stacks() {
    let bvh = load::<TriPacket>(&chain(MAX_DEPTH)).expect("MAX_DEPTH levels load");
    assert_eq!(bvh.depth(), MAX_DEPTH);
    let miss = Ray::new(Vec3::new(0.0, 5.0, 5.0), Vec3::NEG_Z);
    let hit = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::NEG_Z);
    let mut stats = TraversalStats::default();
    assert_eq!(bvh.as_ref().closest_hit_stats(&miss, &mut stats), None);
    assert_eq!(stats.nodes as usize, MAX_DEPTH);
    assert_eq!(stats.items as usize, (WIDTH - 1) * (MAX_DEPTH - 1) + WIDTH);
    assert!(!bvh.occluded(&miss));
    assert_eq!(bvh.closest_t(&hit).map(|b| (b.t, b.prim)), Some((5.0, 0)));
    assert!(bvh.occluded(&hit));
    let bytes = chain(MAX_DEPTH);
    with_aligned(&bytes, 0, |b| {
        let view = BvhRef::<TriPacket>::from_bytes(b).unwrap();
        assert!(!view.occluded(&miss) && view.occluded(&hit));
        assert_eq!(view.closest_hit(&hit).map(|h| h.prim), Some(0));
    });
    assert_eq!(load_err::<TriPacket>(&chain(MAX_DEPTH + 1)), LoadError::TooDeep);
}

/// A slice that is not aligned for the node type is `Misaligned` for the
/// zero-copy loader, while the copying loader loads the very same slice
/// into an equal BVH; at an aligned offset both work.
#[test]
fn misaligned_slices_need_the_copying_loader() {
    let bvh = tri_bvh();
    let bytes = bvh.to_bytes();
    let align = align_of::<Node>();
    assert!((16..=64).contains(&align), "nodes are SIMD aligned; Line covers them");
    for offset in [1, 2, 4, 8, align / 2, align + 4] {
        with_aligned(&bytes, offset, |b| {
            assert_eq!(
                BvhRef::<TriPacket>::from_bytes(b).err(),
                Some(LoadError::Misaligned),
                "offset {offset}"
            );
            assert_eq!(Bvh::<TriPacket>::from_bytes(b).unwrap(), bvh, "offset {offset}");
        });
    }
    with_aligned(&bytes, align, |b| {
        let view = BvhRef::<TriPacket>::from_bytes(b).unwrap();
        for r in probe_rays() {
            assert_eq!(view.closest_hit(&r), bvh.closest_hit(&r));
        }
    });
}

/// An unused packet lane (prim `u32::MAX`) must hold no triangle: the
/// traversal tests all four lanes, so a finite triangle there is "hit"
/// without a primitive. Loading such a blob must fail: otherwise a ray
/// through a phantom copy of a real triangle, just in front of it, would be
/// occluded while `closest_hit` finds nothing.
#[test]
fn triangles_in_unused_lanes_are_rejected() {
    let bvh = tri_bvh();
    let item = bvh.items().iter().position(|p| p.len() < 4).unwrap();
    let packet = bvh.items()[item];
    let real = [0, 1, 2].map(|k| packet.vertex(0, k));
    let bytes = edit_items::<TriPacket>(&bvh.to_bytes(), |it| {
        it[item].set_lane(packet.len(), u32::MAX, real.map(|v| v * 0.999));
    });
    // From the centre out through the real triangle: the phantom comes first.
    let r = Ray::new(Vec3::ZERO, real[0] + real[1] + real[2]);
    assert_eq!(bvh.closest_t(&r).map(|b| b.prim), Some(packet.prims[0]));
    assert_eq!(load::<TriPacket>(&bytes).err(), Some(LoadError::BadItem { item }));
}

/// `bytes` with each `(region, position, mask)` flip applied: region 0 is
/// the header, 1 the nodes, 2 the items.
fn flip(bytes: &[u8], flips: &[(usize, prop::sample::Index, u8)]) -> Vec<u8> {
    let n = header(bytes).node_count as usize;
    let regions = [0..HEADER, HEADER..HEADER + n * NODE, HEADER + n * NODE..bytes.len()];
    let mut out = bytes.to_vec();
    for (region, at, mask) in flips {
        let r = &regions[*region];
        if !r.is_empty() {
            out[r.start + at.index(r.len())] ^= mask;
        }
    }
    out
}

/// The flipped blob either fails to load (both loaders agreeing on the
/// error) or loads and behaves: it serializes back to the same bytes (but
/// for the reserved header words), and
/// every probe ray's closest hit is absent or lies in the ray's range with
/// a valid primitive id, the full hit record agreeing with it.
fn check_flipped<P: Primitive>(bytes: &[u8]) -> Result<(), TestCaseError> {
    let Ok(bvh) = load::<P>(bytes) else { return Ok(()) };
    // The reserved header words are not kept (they are written as zero).
    prop_assert!(
        bvh.to_bytes() == edit_header(bytes, |h| h.reserved = [0; 8]),
        "not re-serialized as loaded"
    );
    for r in probe_rays() {
        let _ = bvh.occluded(&r);
        let best = bvh.closest_t(&r);
        if let Some(b) = best {
            prop_assert!(b.t >= r.t_min && b.t <= r.t_max, "t = {} outside {:?}", b.t, r);
            prop_assert!(b.prim < bvh.prim_count());
            if r.t_max.is_finite() {
                prop_assert!(b.t.is_finite());
            }
        }
        let hit = bvh.closest_hit(&r);
        if best.is_some_and(|b| b.t.is_finite()) {
            prop_assert_eq!(hit.map(|h| (h.t, h.prim)), best.map(|b| (b.t, b.prim)));
        } else {
            prop_assert!(hit.is_none());
        }
    }
    Ok(())
}

/// The valid blobs the flips start from: triangles, spheres, capsules.
static BLOBS: LazyLock<[Vec<u8>; 3]> =
    LazyLock::new(|| [tri_bvh().to_bytes(), sphere_bvh().to_bytes(), capsule_bvh().to_bytes()]);

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 1024,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0xB17E5),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Random byte flips in the header, nodes or items of a valid triangle,
    /// sphere or capsule blob never make a loader panic, and whatever still
    /// loads traverses without panicking and answers sanely.
    #[test]
    fn random_byte_flips_never_panic(
        kind in 0usize..3,
        flips in prop::collection::vec((0usize..3, any::<prop::sample::Index>(), 1u8..=255), 1..6),
    ) {
        match kind {
            0 => check_flipped::<TriPacket>(&flip(&BLOBS[0], &flips))?,
            1 => check_flipped::<SphereItem>(&flip(&BLOBS[1], &flips))?,
            _ => check_flipped::<CapsuleItem>(&flip(&BLOBS[2], &flips))?,
        }
    }
}
