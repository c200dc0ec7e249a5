//! Digests of final states: two runs whose digests agree ended in the same states, bit for bit.

/// A 64-bit FNV-1a hash, in hex, of a sequence of words (little-endian bytes).
pub fn fnv_hex(words: impl IntoIterator<Item = u64>) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for x in words {
        for byte in x.to_le_bytes() {
            h ^= u64::from(byte);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    format!("{h:016x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_empty_sequence_hashes_to_the_offset_basis() {
        assert_eq!(fnv_hex([]), "cbf29ce484222325");
        assert_ne!(fnv_hex([1]), fnv_hex([2]));
        assert_ne!(fnv_hex([1, 2]), fnv_hex([2, 1]));
    }
}
