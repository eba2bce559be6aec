//! Loading a BVH from bytes: any bytes are a `LoadError` or a BVH whose
//! traversal stays in bounds, terminates and answers hits in range; a
//! loaded BVH's own bytes load back to the same BVH.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rt_accel::{Bvh, BvhRef, TriPacket};
use rt_fuzz::{check_t, ray};

fuzz_target!(|data: &[u8]| {
    // The first 64 bytes choose rays; the rest is the file. A valid seed
    // BVH is mutated from time to time, so that loading gets past the
    // header checks.
    let (rays, mut bytes) = data.split_at(data.len().min(64));
    let seed;
    if bytes.first() == Some(&0xB5) {
        let pos = [
            rt_core::glam::Vec3::ZERO,
            rt_core::glam::Vec3::X,
            rt_core::glam::Vec3::Y,
            rt_core::glam::Vec3::Z,
        ];
        let bvh = rt_accel::build_triangles(&pos, &[[0, 1, 2], [0, 2, 3]], &Default::default())
            .expect("a valid mesh");
        let mut b = bvh.to_bytes();
        for (k, &x) in bytes.iter().skip(1).take(8).enumerate() {
            let i = (usize::from(x) * 7 + k * 131) % b.len();
            b[i] ^= x;
        }
        seed = b;
        bytes = &seed;
    }
    // The borrowed view needs aligned bytes: copy into 16-byte words.
    let mut words = vec![0u128; bytes.len().div_ceil(16)];
    let aligned = &mut bytemuck::cast_slice_mut::<u128, u8>(&mut words)[..bytes.len()];
    aligned.copy_from_slice(bytes);
    let aligned = &*aligned;
    let owned = Bvh::<TriPacket>::from_bytes(bytes);
    let Ok(view) = BvhRef::<TriPacket>::from_bytes(aligned) else {
        assert!(owned.is_err(), "owned and borrowed loaders disagree");
        return;
    };
    let owned = owned.expect("the borrowed loader accepted it");
    // Reserved header bytes are not checked, so compare the canonical form.
    let canonical = owned.to_bytes();
    let again = Bvh::<TriPacket>::from_bytes(&canonical).expect("its own bytes load");
    assert_eq!(again.to_bytes(), canonical, "round trip");
    let mut u = arbitrary::Unstructured::new(rays);
    for _ in 0..4 {
        let Ok(r) = ray(&mut u) else { break };
        let hit = view.closest_hit(&r);
        if let Some(h) = hit {
            check_t(&r, h.t, "loaded BVH");
        }
        assert_eq!(view.occluded(&r), hit.is_some());
        assert_eq!(owned.closest_hit(&r).map(|h| h.t), hit.map(|h| h.t));
    }
});
