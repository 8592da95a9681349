//! FNV-1a fingerprints that tell two outputs apart without storing them: the BVH's tree
//! hash (`bvh::timing::tree_hash`: the same tree after a change to the builder) and the
//! ray bench's answers hash (`igi bench rays`: two traversals answered alike). Not part
//! of the paper; the checks behind the lab log's "the same tree" and "the same
//! answers".

/// 64-bit FNV-1a over `items`, each folded in as one value (bytes or 32-bit words: the
/// same items give the same hash, so figures printed before stay comparable).
pub fn fnv1a(items: impl IntoIterator<Item = u64>) -> u64 {
    items.into_iter().fold(0xcbf2_9ce4_8422_2325, |h, w| {
        (h ^ w).wrapping_mul(0x100_0000_01b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        // FNV-1a 64 of "" and of "a" (the published test vectors), bytes as items.
        assert_eq!(fnv1a([]), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a([b'a' as u64]), 0xaf63_dc4c_8601_ec8c);
        assert_ne!(fnv1a([1, 2]), fnv1a([2, 1]));
    }
}
