//! The `.btfpca` container: round trips, and hostile input never panics.

mod common;

use std::sync::OnceLock;

use btf::{BtfError, BtfPca, BtfPcaParams, Sampling, Storage};
use common::analytic_pca;
use proptest::prelude::*;

fn small(storage: Storage, mean_storage: Storage) -> BtfPca {
    let params = BtfPcaParams {
        components: 3,
        storage,
        mean_storage,
        ..Default::default()
    };
    analytic_pca(Sampling::H1, 2, &params)
}

fn valid_bytes() -> &'static [u8] {
    static BYTES: OnceLock<Vec<u8>> = OnceLock::new();
    BYTES.get_or_init(|| small(Storage::U8, Storage::U16).to_bytes())
}

#[test]
fn round_trip_every_storage() {
    for (st, mst) in [
        (Storage::U8, Storage::U8),
        (Storage::U8, Storage::U16),
        (Storage::U16, Storage::F32),
        (Storage::F32, Storage::F32),
    ] {
        let pca = small(st, mst);
        let bytes = pca.to_bytes();
        let back = BtfPca::from_bytes(&bytes).unwrap();
        assert_eq!(back, pca);
        assert_eq!((back.storage(), back.mean_storage()), (st, mst));
        assert_eq!(bytes.len(), 692 + pca.payload_bytes());
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.btfpca");
    let pca = small(Storage::U8, Storage::U16);
    pca.write(&path).unwrap();
    assert_eq!(BtfPca::read(&path).unwrap(), pca);
}

#[test]
fn truncated_file_names_the_file_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.btfpca");
    let bytes = valid_bytes();
    std::fs::write(&path, &bytes[..bytes.len() - 10]).unwrap();
    let err = BtfPca::read(&path).unwrap_err();
    assert!(
        matches!(
            err,
            BtfError::Format {
                field: "file length",
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("cut.btfpca"));
}

#[test]
fn impossible_sizes_are_rejected_before_allocating() {
    // A header claiming a 65535² texture with a consistent declared length and checksum is
    // still rejected: the sizes must match the bytes present.
    let mut bytes = valid_bytes().to_vec();
    bytes[16..20].copy_from_slice(&65535u32.to_le_bytes());
    bytes[20..24].copy_from_slice(&u32::MAX.to_le_bytes());
    fix_crc(&mut bytes);
    let err = BtfPca::from_bytes(&bytes).unwrap_err();
    assert!(
        matches!(
            err,
            BtfError::Format {
                field: "file length",
                ..
            }
        ),
        "{err}"
    );
    // c_j > 80.
    let mut bytes = valid_bytes().to_vec();
    bytes[40..44].copy_from_slice(&200u32.to_le_bytes());
    fix_crc(&mut bytes);
    assert!(matches!(
        BtfPca::from_bytes(&bytes),
        Err(BtfError::Format {
            field: "slot components/rank",
            ..
        })
    ));
    // A flipped payload bit fails the checksum.
    let mut bytes = valid_bytes().to_vec();
    let n = bytes.len();
    bytes[n - 20] ^= 1;
    assert!(matches!(
        BtfPca::from_bytes(&bytes),
        Err(BtfError::Format {
            field: "checksum",
            ..
        })
    ));
}

fn fix_crc(bytes: &mut [u8]) {
    let n = bytes.len() - 4;
    let crc = crc32fast::hash(&bytes[..n]);
    bytes[n..].copy_from_slice(&crc.to_le_bytes());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    /// Mutated, truncated or extended files give `Err` or `Ok`, never a panic; with the
    /// checksum recomputed, mutations reach the field checks behind it.
    #[test]
    fn hostile_input_never_panics(
        edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 0..8),
        cut in any::<usize>(),
        mode in 0u8..4,
        fix in any::<bool>(),
    ) {
        let mut bytes = valid_bytes().to_vec();
        for (at, value) in edits {
            let n = bytes.len();
            // Half of the edits hit the 692-byte header and slot table.
            let at = if at % 2 == 0 { at % 692.min(n) } else { at % n };
            bytes[at] = value;
        }
        match mode {
            0 => bytes.truncate(cut % (bytes.len() + 1)),
            1 => bytes.extend(std::iter::repeat_n(0xA5, cut % 64)),
            _ => {}
        }
        if fix && bytes.len() >= 4 {
            fix_crc(&mut bytes);
        }
        let _ = BtfPca::from_bytes(&bytes);
    }
}
