// mirror_list.wgsl: the layout of the list of mirrored pixels, which the direct pass
// fills (direct.wgsl's mirror_list) and the mirror indirect stage reads (indirect.wgsl's
// main_list): [s] counts the pixels of bucket s, one bucket per interleaving subset, and
// bucket s starts at MAX_SUBSETS + s mirror_bucket_size().

#import params

// Most interleaving subsets (frame.rs MAX_SUBSETS).
const MAX_SUBSETS: u32 = 64u;

// Room for the pixels of one interleaving subset in the list of mirrored pixels
// (direct.wgsl's mirror_list): every n x m tile of the full-resolution image, partial
// ones at the edges included, holds one pixel of each subset.
fn mirror_bucket_size() -> u32 {
    let n = params.interleave_n;
    let m = params.interleave_m;
    return ((params.width + n - 1u) / n) * ((params.height + m - 1u) / m);
}
