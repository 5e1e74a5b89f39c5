//! The `.cpca` container against corrupt and hostile input: every failure is an error,
//! never a panic or a huge allocation.

mod compress_common;

use anim_pca::AnimPcaError;
use anim_pca::compress::{Compressed, CpcaParams, crc32};
use proptest::prelude::*;

fn sample(time: Option<usize>) -> Vec<u8> {
    let frames = compress_common::rigid_parts(2, 12, 5);
    let tris: Vec<[u32; 3]> = (0..20).map(|i| [i, i + 1, i + 2]).collect();
    let p = CpcaParams {
        clusters: 2,
        components: 2,
        time_components: time,
        bits_components: 11,
        bits_weights: 7,
        ..CpcaParams::default()
    };
    Compressed::encode(&frames, &tris, 30.0, &p)
        .unwrap()
        .to_bytes()
}

/// Rewrites the checksum so that a field edit reaches the field validation.
fn reseal(bytes: &mut [u8]) {
    let n = bytes.len() - 4;
    let crc = crc32(&bytes[..n]);
    bytes[n..].copy_from_slice(&crc.to_le_bytes());
}

#[test]
fn truncation_at_every_length_is_an_error() {
    for time in [None, Some(3)] {
        let bytes = sample(time);
        assert!(Compressed::from_bytes(&bytes).is_ok());
        for len in 0..bytes.len() {
            match Compressed::from_bytes(&bytes[..len]) {
                Err(AnimPcaError::Truncated { .. }) => {}
                other => panic!("length {len}: {other:?}"),
            }
        }
    }
}

#[test]
fn flipped_bytes_fail_the_checksum() {
    let bytes = sample(Some(3));
    for i in 52..bytes.len() {
        let mut b = bytes.clone();
        b[i] ^= 0x5a;
        match Compressed::from_bytes(&b) {
            Err(AnimPcaError::ChecksumMismatch { .. }) => {}
            other => panic!("byte {i}: {other:?}"),
        }
    }
    // A flipped header byte is an error too (magic, version, length or checksum).
    for i in 0..52 {
        let mut b = bytes.clone();
        b[i] ^= 0x01;
        assert!(Compressed::from_bytes(&b).is_err(), "header byte {i}");
    }
}

#[test]
fn huge_header_fields_are_refused_without_allocating() {
    let bytes = sample(Some(3));
    // (offset, name of the field the error names)
    for (offset, field) in [
        (12, "section RNGE"), // V
        (16, "frames"),       // F
        (20, "clusters"),     // k > V
        (24, "components"),   // c > 3F
        (28, "time_components"),
        (36, "triangles"),
    ] {
        for value in [u32::MAX, u32::MAX / 3, 1 << 30] {
            let mut b = bytes.clone();
            b[offset..offset + 4].copy_from_slice(&value.to_le_bytes());
            reseal(&mut b);
            match Compressed::from_bytes(&b) {
                Err(AnimPcaError::InvalidFile { field: f, .. }) => {
                    assert!(
                        f == field || f.starts_with("section") || f == "sizes",
                        "offset {offset} = {value}: field {f}"
                    );
                }
                other => panic!("offset {offset} = {value}: {other:?}"),
            }
        }
    }
    for (offset, value, field) in [(32, 0u8, "bits_components"), (33, 40, "bits_weights")] {
        let mut b = bytes.clone();
        b[offset] = value;
        reseal(&mut b);
        assert!(
            matches!(Compressed::from_bytes(&b), Err(AnimPcaError::InvalidFile { field: f, .. }) if f == field)
        );
    }
    // A declared length of 2⁶⁴ − 1 is a truncation, not an allocation.
    let mut b = bytes.clone();
    b[44..52].copy_from_slice(&u64::MAX.to_le_bytes());
    assert!(matches!(
        Compressed::from_bytes(&b),
        Err(AnimPcaError::Truncated { .. })
    ));
}

#[test]
fn hostile_payloads_are_refused() {
    let bytes = sample(None);
    let read = Compressed::from_bytes(&bytes).unwrap();
    // A NaN range in RNGE (section payload starts at 52 + 8).
    let mut b = bytes.clone();
    b[60..64].copy_from_slice(&f32::NAN.to_le_bytes());
    reseal(&mut b);
    assert!(matches!(
        Compressed::from_bytes(&b),
        Err(AnimPcaError::InvalidFile { field: "range", .. })
    ));
    // lo > hi.
    let mut b = bytes.clone();
    b[60..64].copy_from_slice(&1e30f32.to_le_bytes());
    reseal(&mut b);
    assert!(Compressed::from_bytes(&b).is_err());
    // Unknown flags, an old or future version, wrong magic.
    for (offset, value) in [(10usize, 0x80u8), (8, 1), (8, 3), (1, b'X')] {
        let mut b = bytes.clone();
        b[offset] = value;
        reseal(&mut b);
        assert!(
            matches!(
                Compressed::from_bytes(&b),
                Err(AnimPcaError::InvalidFile { .. })
            ),
            "offset {offset}"
        );
    }
    // Trailing bytes.
    let mut b = bytes.clone();
    b.push(0);
    assert!(Compressed::from_bytes(&b).is_err());
    assert_eq!(read.vertices(), 24);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn random_mutations_never_panic(
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
        cut in any::<prop::sample::Index>(),
        seal in any::<bool>(),
        time in any::<bool>(),
    ) {
        let mut b = sample(if time { Some(3) } else { None });
        for (i, v) in &edits {
            let i = i.index(b.len());
            b[i] = *v;
        }
        if seal {
            reseal(&mut b);
        }
        let _ = Compressed::from_bytes(&b);
        let n = cut.index(b.len() + 1);
        let _ = Compressed::from_bytes(&b[..n]);
    }
}
