//! Fuzz target: the MERL `.binary` reader must never panic, whatever the bytes,
//! and must allocate only in proportion to the input's length.
#![no_main]

use bv_core::frame::from_spherical;
use bv_core::measured::{Interpolation, MerlTable};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(t) = MerlTable::read_from(data, data.len() as u64, "fuzz") {
        // Whatever is accepted is consistent with its own header.
        assert_eq!(t.dims().file_len(), data.len() as u64);
        assert!(t.data().iter().all(|x| x.is_finite() && *x >= 0.0));
        // And can be looked up without panicking.
        let (wi, wo) = (from_spherical(0.3, 0.2), from_spherical(1.1, 2.5));
        for mode in [Interpolation::Nearest, Interpolation::Trilinear] {
            assert!(t.lookup(wi, wo, mode).is_finite());
        }
    }
});
