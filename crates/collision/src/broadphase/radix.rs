//! LSD radix sort on 64-bit keys, order-preserving integer keys for floats, and a parallel
//! sort (radix-sorted chunks merged by a parallel merge) whose result does not depend on the
//! number of threads.
//!
//! Radix sort for the broadphase follows Terdiman, "Radix Sort Revisited" (2000) (float keys
//! by flipping bits) and the GPU sort-and-sweep of Le Grand, GPU Gems 3 ch. 32.

const BITS: u32 = 11;
const BUCKETS: usize = 1 << BITS;
/// Digits of a 64-bit key.
const PASSES: usize = 64usize.div_ceil(BITS as usize);

/// Sorts `items` by `key(item)` ascending with a stable LSD radix sort (11-bit digits; digits
/// on which all keys agree are skipped). `scratch` is reused storage.
pub fn radix_sort_by_key<T: Copy, K: Fn(&T) -> u64>(
    items: &mut Vec<T>,
    scratch: &mut Vec<T>,
    key: K,
) {
    let n = items.len();
    if n < 64 {
        items.sort_by_key(|t| key(t));
        return;
    }
    // One pass over the data builds every digit's histogram (48 KB on the stack rather
    // than the heap: the grids sort at every update, and the steady state allocates nothing).
    let mut hist = [[0u32; BUCKETS]; PASSES];
    for t in items.iter() {
        let k = key(t);
        for (p, h) in hist.iter_mut().enumerate() {
            h[((k >> (p as u32 * BITS)) as usize) & (BUCKETS - 1)] += 1;
        }
    }
    scratch.clear();
    scratch.extend_from_slice(items);
    let (mut src, mut dst) = (items, scratch);
    let mut swapped = false;
    for (p, h) in hist.iter().enumerate() {
        if h.iter().any(|&c| c as usize == n) {
            continue; // every key has the same digit: this pass would not move anything
        }
        let mut offsets = [0u32; BUCKETS];
        let mut sum = 0u32;
        for (o, &c) in offsets.iter_mut().zip(h.iter()) {
            *o = sum;
            sum += c;
        }
        let shift = p as u32 * BITS;
        for t in src.iter() {
            let d = ((key(t) >> shift) as usize) & (BUCKETS - 1);
            dst[offsets[d] as usize] = *t;
            offsets[d] += 1;
        }
        std::mem::swap(&mut src, &mut dst);
        swapped = !swapped;
    }
    if swapped {
        // The sorted data is in the scratch buffer: copy it back.
        dst.copy_from_slice(src);
    }
}

/// Sorts `u64` keys ascending (radix sort).
pub fn radix_sort_u64(keys: &mut Vec<u64>) {
    let mut scratch = Vec::new();
    radix_sort_by_key(keys, &mut scratch, |&k| k);
}

/// [`par_sort_u64`] with reused scratch storage: up to `2 × PAR_CHUNK` keys are sorted on
/// this thread without allocating once `scratch` has grown; more take the parallel path.
pub fn par_sort_u64_with(keys: &mut Vec<u64>, scratch: &mut Vec<u64>) {
    if keys.len() <= 2 * PAR_CHUNK {
        radix_sort_by_key(keys, scratch, |&k| k);
    } else {
        par_sort_u64(keys);
    }
}

/// Chunk size of the parallel sort: fixed, so the work split (and the result) does not
/// depend on the number of threads.
pub const PAR_CHUNK: usize = 1 << 15;

/// Sorts distinct `u64` keys ascending: chunks of [`PAR_CHUNK`] keys are radix-sorted in
/// parallel, then merged pairwise by a parallel merge (rayon). Without the `parallel`
/// feature this is [`radix_sort_u64`]. The result is the sorted sequence whatever the
/// thread count.
pub fn par_sort_u64(keys: &mut Vec<u64>) {
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        if keys.len() <= 2 * PAR_CHUNK {
            radix_sort_u64(keys);
            return;
        }
        keys.par_chunks_mut(PAR_CHUNK).for_each(|c| {
            let mut v = c.to_vec();
            radix_sort_u64(&mut v);
            c.copy_from_slice(&v);
        });
        let mut width = PAR_CHUNK;
        let mut buf = vec![0u64; keys.len()];
        let mut in_keys = true;
        while width < keys.len() {
            let (src, dst): (&[u64], &mut [u64]) = if in_keys {
                (&keys[..], &mut buf[..])
            } else {
                (&buf[..], &mut keys[..])
            };
            src.par_chunks(2 * width)
                .zip(dst.par_chunks_mut(2 * width))
                .for_each(|(s, d)| {
                    let mid = width.min(s.len());
                    par_merge(&s[..mid], &s[mid..], d);
                });
            in_keys = !in_keys;
            width *= 2;
        }
        if !in_keys {
            keys.copy_from_slice(&buf);
        }
    }
    #[cfg(not(feature = "parallel"))]
    radix_sort_u64(keys);
}

/// Merges sorted `a` and `b` into `out` (`out.len() == a.len() + b.len()`), splitting the
/// work recursively at the median of the larger input (rayon::join).
#[cfg(feature = "parallel")]
fn par_merge(a: &[u64], b: &[u64], out: &mut [u64]) {
    const SEQ: usize = 1 << 14;
    if a.len() + b.len() <= SEQ {
        merge(a, b, out);
        return;
    }
    let (big, small, big_first) = if a.len() >= b.len() {
        (a, b, true)
    } else {
        (b, a, false)
    };
    let mid = big.len() / 2;
    let pivot = big[mid];
    let split = small.partition_point(|&x| x < pivot);
    let (out_lo, out_hi) = out.split_at_mut(mid + split);
    let (b_lo, b_hi) = big.split_at(mid);
    let (s_lo, s_hi) = small.split_at(split);
    if big_first {
        rayon::join(
            || par_merge(b_lo, s_lo, out_lo),
            || par_merge(b_hi, s_hi, out_hi),
        );
    } else {
        rayon::join(
            || par_merge(s_lo, b_lo, out_lo),
            || par_merge(s_hi, b_hi, out_hi),
        );
    }
}

/// Sequential merge of two sorted slices.
pub fn merge(a: &[u64], b: &[u64], out: &mut [u64]) {
    let (mut i, mut j) = (0, 0);
    for o in out.iter_mut() {
        if j >= b.len() || (i < a.len() && a[i] <= b[j]) {
            *o = a[i];
            i += 1;
        } else {
            *o = b[j];
            j += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(seed: &mut u64) -> u64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        *seed ^ (*seed >> 29)
    }

    #[test]
    fn radix_matches_std_sort() {
        let mut s = 7;
        for &n in &[0usize, 5, 63, 64, 1000, 70_000] {
            let mut v: Vec<u64> = (0..n).map(|_| lcg(&mut s) >> (n % 40)).collect();
            let mut w = v.clone();
            radix_sort_u64(&mut v);
            w.sort_unstable();
            assert_eq!(v, w);
        }
    }

    #[test]
    fn par_sort_matches_std_sort() {
        let mut s = 3;
        let mut v: Vec<u64> = (0..200_000).map(|_| lcg(&mut s)).collect();
        let mut w = v.clone();
        par_sort_u64(&mut v);
        w.sort_unstable();
        assert_eq!(v, w);
    }
}
