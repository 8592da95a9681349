//! Work on all threads of rayon's pool outside the recursive build: chunked passes over
//! slices, vectors written once by the threads that fill them, and the reuse of a
//! finished phase's allocation.

/// Threads of the work-stealing pool the build runs on (rayon's global pool: one per core).
pub(super) fn threads() -> usize {
    rayon_core::current_num_threads()
}

/// Runs `f(chunk_start, chunk)` over `data` split into chunks on all threads; returns
/// the results in chunk order. Four chunks per thread, taken by whichever thread is free,
/// so that uneven work (the few triangles that split clipping cuts) does not wait for
/// one thread.
pub(in crate::bvh) fn par_chunks<T: Send, R: Send, F>(data: &mut [T], f: F) -> Vec<R>
where
    F: Fn(usize, &mut [T]) -> R + Sync,
{
    let mut none = vec![(); data.len()];
    par_chunks_zip(data, &mut none, |base, chunk, _| f(base, chunk))
}

/// [`par_chunks`] over two slices of one length, split alike: `f(chunk_start, a, b)`.
pub(super) fn par_chunks_zip<A: Send, B: Send, R: Send, F>(a: &mut [A], b: &mut [B], f: F) -> Vec<R>
where
    F: Fn(usize, &mut [A], &mut [B]) -> R + Sync,
{
    assert_eq!(a.len(), b.len(), "slices of one length");
    let Some(chunk) = chunk_len(a.len()) else {
        return vec![f(0, a, b)];
    };
    let mut results: Vec<Option<R>> = a.chunks(chunk).map(|_| None).collect();
    let f = &f;
    rayon_core::scope(|s| {
        let chunks = a.chunks_mut(chunk).zip(b.chunks_mut(chunk));
        for (k, ((ca, cb), r)) in chunks.zip(&mut results).enumerate() {
            s.spawn(move |_| *r = Some(f(k * chunk, ca, cb)));
        }
    });
    results
        .into_iter()
        .map(|r| r.expect("every chunk ran"))
        .collect()
}

/// Two vectors of `n` items (the first with room for `spare` more) made on all threads:
/// items i are `item(i)`, and `reduce` runs over each chunk of the first once it is
/// written (its results come in chunk order). The threads write the memory once: zeroed
/// first, as `vec!` does, it would be written twice, the first time in one thread when
/// the allocator reuses memory.
pub(super) fn par_vec2<A, B, R, I, G>(
    n: usize,
    spare: usize,
    item: I,
    reduce: G,
) -> (Vec<A>, Vec<B>, Vec<R>)
where
    A: Send + Sync,
    B: Send,
    R: Send,
    I: Fn(usize) -> (A, B) + Sync,
    G: Fn(&[A]) -> R + Sync,
{
    let mut va: Vec<A> = Vec::with_capacity(n + spare);
    let mut vb: Vec<B> = Vec::with_capacity(n);
    let results = par_chunks_zip(
        &mut va.spare_capacity_mut()[..n],
        &mut vb.spare_capacity_mut()[..n],
        |base, ca, cb| {
            for (k, (sa, sb)) in ca.iter_mut().zip(cb).enumerate() {
                let (a, b) = item(base + k);
                sa.write(a);
                sb.write(b);
            }
            // SAFETY: every element of the chunk was initialised just above, and
            // MaybeUninit<A> has the layout of A.
            let done = unsafe { &*(ca as *const [std::mem::MaybeUninit<A>] as *const [A]) };
            reduce(done)
        },
    );
    // SAFETY: par_chunks_zip ran the closure above over every chunk of the first n
    // elements of both (a panic in it would have ended this function), and it
    // initialised each of them.
    unsafe {
        va.set_len(n);
        vb.set_len(n);
    }
    (va, vb, results)
}

/// An empty vector of `B` in the allocation of `v`, whose items are dropped, where that
/// holds `n` of them (the same alignment, and a size that divides); otherwise a new one.
/// A buffer that a finished phase wrote has its pages mapped, a new one does not (see
/// `build_impl`).
pub(in crate::bvh) fn reuse_vec<A: bytemuck::NoUninit, B: bytemuck::AnyBitPattern>(
    mut v: Vec<A>,
    n: usize,
) -> Vec<B> {
    v.clear();
    match bytemuck::allocation::try_cast_vec::<A, B>(v) {
        Ok(b) if b.capacity() >= n => b,
        _ => Vec::with_capacity(n),
    }
}

/// The chunk length of [`par_chunks`] for `n` items, or None where one thread does it all.
pub(super) fn chunk_len(n: usize) -> Option<usize> {
    let t = threads();
    (t > 1 && n >= 4096).then(|| n.div_ceil(4 * t))
}
