//! Binary masks as `bool` planes (row-major, `w x h`): closing and opening (equal to the
//! grey-scale operators on 0/1 images; or keeping the dashed lines the opening would drop),
//! hole filling and small-component removal with the labelling, splitting at narrow necks,
//! convex hulls per component or over the arcs of one broken outline; the clean-up the
//! segmenting tasks (material regions, transparency masks) share.

use crate::label::Forest;
use crate::morph::{check_kernel, runs};
use crate::{
    Connectivity, MorphShape, Outside, close, distance_to_background, label, max_filter, open,
};
use polar_image::Gray;

use crate::Error;

/// Morphological closing then opening with an ellipse of diameter `k` (odd): bridges gaps
/// narrower than `k` and removes specks narrower than `k`. Equal to [`grey_close_open`];
/// computed on byte run distances (16 pixels per SIMD lane group) where the ellipse is
/// narrower than 509 pixels.
pub fn close_open(m: &[bool], w: usize, h: usize, k: usize) -> Result<Vec<bool>, Error> {
    Ok(closed_and_opened(m, w, h, k)?.1)
}

/// [`close_open`], except that the thin parts of the closing, those the opening drops,
/// stay where they touch what the opening keeps, hold at least `k²` pixels and `m` covers
/// at least `min_density` of them (each 8-connected part judged on its own): a line of `m`
/// broken by short gaps (an outline drawn in dashes), which the closing joins and the
/// opening drops as narrower than `k`, stays with the blob it leads from; a chain the
/// closing draws through scattered specks, mostly gaps, goes, and so does a part smaller
/// than the element, a bump of the blob's outline rather than a line. `min_density` above 1
/// keeps nothing more.
pub fn close_open_keeping_lines(
    m: &[bool],
    w: usize,
    h: usize,
    k: usize,
    min_density: f32,
) -> Result<Vec<bool>, Error> {
    let (closed, opened) = closed_and_opened(m, w, h, k)?;
    let thin: Vec<bool> = closed.iter().zip(&opened).map(|(&c, &o)| c && !o).collect();
    let (lab, n) = components(&thin, w, h)?;
    let touching = grown(&opened, w, h, 1)?;
    // Per thin part: whether it touches the opening's pixels, its pixels, those in `m`.
    let (mut touches, mut all, mut on) =
        (vec![false; n + 1], vec![0usize; n + 1], vec![0usize; n + 1]);
    for (i, &l) in lab.iter().enumerate().filter(|&(_, &l)| l > 0) {
        let c = l as usize;
        touches[c] |= touching[i];
        all[c] += 1;
        on[c] += usize::from(m[i]);
    }
    let keep: Vec<bool> = (0..=n)
        .map(|c| {
            c > 0 && touches[c] && all[c] >= k * k && on[c] as f32 >= min_density * all[c] as f32
        })
        .collect();
    Ok((0..w * h)
        .map(|i| opened[i] || keep[lab[i] as usize])
        .collect())
}

/// The closing of `m` by an ellipse of diameter `k` and that closing's opening.
fn closed_and_opened(
    m: &[bool],
    w: usize,
    h: usize,
    k: usize,
) -> Result<(Vec<bool>, Vec<bool>), Error> {
    check_kernel(k, k)?;
    if k / 2 >= usize::from(u8::MAX) {
        return grey_closed_and_opened(m, w, h, k);
    }
    let element: Vec<Offsets> = runs(MorphShape::Ellipse, k, k)
        .iter()
        .map(|r| Offsets {
            dy: r.dy as isize - (k / 2) as isize,
            left: (k / 2 - r.x0) as u8,
            right: (r.x0 + r.len - 1 - k / 2) as u8,
        })
        .collect();
    let closed = binary_morph(
        &binary_morph(m, w, h, &element, false),
        w,
        h,
        &element,
        true,
    );
    let opened = binary_morph(
        &binary_morph(&closed, w, h, &element, true),
        w,
        h,
        &element,
        false,
    );
    Ok((closed, opened))
}

/// `close` then `open` with [`MorphShape::Ellipse`] of diameter `k` on the 0/1 image of
/// `m` (out-of-image pixels ignored), thresholded at 0.5.
pub fn grey_close_open(m: &[bool], w: usize, h: usize, k: usize) -> Result<Vec<bool>, Error> {
    Ok(grey_closed_and_opened(m, w, h, k)?.1)
}

/// [`closed_and_opened`] with the grey-scale operators.
fn grey_closed_and_opened(
    m: &[bool],
    w: usize,
    h: usize,
    k: usize,
) -> Result<(Vec<bool>, Vec<bool>), Error> {
    let src = Gray::from_vec(w, h, m.iter().map(|&b| f32::from(u8::from(b))).collect())
        .expect("mask size");
    let (mut a, mut b) = (Gray::new(w, h), Gray::new(w, h));
    close(&src, &mut a, MorphShape::Ellipse, k, k)?;
    open(&a, &mut b, MorphShape::Ellipse, k, k)?;
    let set = |g: &Gray<f32>| g.as_slice().iter().map(|&v| v > 0.5).collect();
    Ok((set(&a), set(&b)))
}

/// One row of a structuring element that contains its centre column: row offset `dy`
/// from the anchor, reaching `left` columns to the left and `right` to the right.
struct Offsets {
    dy: isize,
    left: u8,
    right: u8,
}

/// Dilation of `m` by `element` (or, with `erode`, erosion: the dilation of the
/// complement, complemented), pixels outside the image ignored. A pixel is hit when, in
/// some element row, the nearest set pixel of that image row to its left lies within
/// `left` or the nearest to its right within `right`.
fn binary_morph(m: &[bool], w: usize, h: usize, element: &[Offsets], erode: bool) -> Vec<bool> {
    use rayon::prelude::*;
    let row = w.max(1);
    // Per pixel, the distance along its row to the nearest set pixel at or left of it and
    // at or right of it (saturated: the element reaches at most 254 columns).
    let (mut left, mut right) = (vec![0u8; w * h], vec![0u8; w * h]);
    left.par_chunks_mut(row)
        .zip(right.par_chunks_mut(row))
        .zip(m.par_chunks(row))
        .for_each(|((l, r), m)| row_distances(m, !erode, l, r));
    let mut out = vec![false; w * h];
    out.par_chunks_mut(row).enumerate().for_each(|(y, o)| {
        for e in element {
            let Some(sy) = y.checked_add_signed(e.dy).filter(|&sy| sy < h) else {
                continue;
            };
            let (l, r) = (&left[sy * w..(sy + 1) * w], &right[sy * w..(sy + 1) * w]);
            o.iter_mut()
                .zip(l.iter().zip(r))
                .for_each(|(o, (&l, &r))| *o |= (l <= e.left) | (r <= e.right));
        }
        if erode {
            o.iter_mut().for_each(|v| *v = !*v);
        }
    });
    out
}

/// Distances from each pixel of `row` to the nearest pixel equal to `set` at or left of
/// it (`left`) and at or right of it (`right`), saturated at [`u8::MAX`] (none within 254).
fn row_distances(row: &[bool], set: bool, left: &mut [u8], right: &mut [u8]) {
    let mut run = u8::MAX;
    for (d, &v) in left.iter_mut().zip(row) {
        run = if v == set { 0 } else { run.saturating_add(1) };
        *d = run;
    }
    run = u8::MAX;
    for (d, &v) in right.iter_mut().zip(row).rev() {
        run = if v == set { 0 } else { run.saturating_add(1) };
        *d = run;
    }
}

/// Connected-component labels of `m` (0 = outside `m`) and their count.
pub fn components(m: &[bool], w: usize, h: usize) -> Result<(Vec<u32>, usize), Error> {
    let src = Gray::from_vec(w, h, m.iter().map(|&b| u8::from(b)).collect()).expect("mask size");
    let mut lab = Gray::new(w, h);
    let n = label(&src, &mut lab, Connectivity::Eight)?;
    Ok((lab.into_vec(), n))
}

/// Splits a mask into its blobs: 8-connected regions of `m` cut where two blobs meet at a
/// narrow neck. `dist` is any distance of each mask pixel to the outside (0 off the mask).
/// Flooding the pixels from the largest distance down (union-find, as a watershed of
/// `-dist` whose basins merge by their dynamics), two basins meeting at a pixel of
/// distance `d` merge unless `d < neck * min(peak)` of the two basins' peaks and both
/// peaks are at least `min_peak` (a bump of the outline is no blob); a pixel where they
/// stay apart joins the basin of its farthest-inside neighbour. Returns per-pixel labels
/// (`1..=count`, 0 off the mask) and the count; an error if `m` or `dist` is not `w x h`
/// or a mask pixel's distance is not finite.
pub fn split_at_necks(
    m: &[bool],
    dist: &[f32],
    w: usize,
    h: usize,
    neck: f32,
    min_peak: f32,
) -> Result<(Vec<u32>, usize), Error> {
    for len in [m.len(), dist.len()] {
        if len != w * h {
            return Err(Error::SizeMismatch(w, h, len, 1));
        }
    }
    let mut order: Vec<usize> = (0..w * h).filter(|&k| m[k]).collect();
    if order.iter().any(|&k| !dist[k].is_finite()) {
        return Err(Error::NonFinite);
    }
    // Farthest inside first, ties in raster order.
    order.sort_unstable_by(|&a, &b| dist[b].total_cmp(&dist[a]).then(a.cmp(&b)));
    let mut flood = Flood {
        parent: (0..w * h).collect(),
        peak: vec![0.0; w * h],
        done: vec![false; w * h],
    };
    for &k in &order {
        flood.add(k, dist, w, h, |d, low| d >= neck * low || low < min_peak);
    }
    Ok(flood.labels(&order))
}

/// The union-find state of [`split_at_necks`]: each pixel's parent, each basin root's
/// peak distance, and which pixels are flooded.
struct Flood {
    parent: Vec<usize>,
    peak: Vec<f32>,
    done: Vec<bool>,
}

impl Flood {
    /// The root of `k`'s basin (path halving).
    fn root(&mut self, mut k: usize) -> usize {
        while self.parent[k] != k {
            self.parent[k] = self.parent[self.parent[k]];
            k = self.parent[k];
        }
        k
    }

    /// Floods pixel `k` of distance `dist[k]`: a new basin if no 8-neighbour is flooded,
    /// else it joins its farthest-inside neighbour's basin, and the basins it touches
    /// merge where `merge(dist[k], smaller peak)` holds.
    fn add(
        &mut self,
        k: usize,
        dist: &[f32],
        w: usize,
        h: usize,
        merge: impl Fn(f32, f32) -> bool,
    ) {
        let (x, y) = (k % w, k / w);
        let mut best: Option<usize> = None;
        let (mut roots, mut n_roots) = ([0usize; 8], 0);
        for ny in y.saturating_sub(1)..=(y + 1).min(h - 1) {
            for nx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                let j = ny * w + nx;
                if !self.done[j] {
                    continue;
                }
                if best.is_none_or(|b| dist[j] > dist[b]) {
                    best = Some(j);
                }
                let r = self.root(j);
                if !roots[..n_roots].contains(&r) {
                    roots[n_roots] = r;
                    n_roots += 1;
                }
            }
        }
        self.done[k] = true;
        let Some(b) = best else {
            self.peak[k] = dist[k];
            return;
        };
        let home = self.root(b);
        self.parent[k] = home;
        for &r in &roots[..n_roots] {
            let (a, r) = (self.root(home), self.root(r));
            if a != r && merge(dist[k], self.peak[a].min(self.peak[r])) {
                self.parent[r] = a;
                self.peak[a] = self.peak[a].max(self.peak[r]);
            }
        }
    }

    /// Labels `1..=count` of the basins of the flooded pixels `order` (0 elsewhere).
    fn labels(&mut self, order: &[usize]) -> (Vec<u32>, usize) {
        let n = self.parent.len();
        let (mut id, mut labels, mut count) = (vec![0u32; n], vec![0u32; n], 0usize);
        for &k in order {
            let r = self.root(k);
            if id[r] == 0 {
                count += 1;
                id[r] = count as u32;
            }
            labels[k] = id[r];
        }
        (labels, count)
    }
}

/// `m` cut into its blobs ([`split_at_necks`] on the Euclidean distance to the outside,
/// the frame's edge counting as outside), the pixels where two blobs meet left out, so that
/// each blob is an 8-connected component of its own: two objects whose masks touch through
/// a narrow bridge (a shared shadow, a strip of floor, a glint between them) take a convex
/// hull each. A neck cuts where it is narrower than [`BLOB_NECK`] of the smaller blob's
/// inscribed radius and both radii reach [`BLOB_RADIUS`] of the frame's shorter side (the
/// thinner arcs of one rim stay together).
pub fn blobs_apart(m: &[bool], w: usize, h: usize) -> Result<Vec<bool>, Error> {
    if m.len() != w * h {
        return Err(Error::SizeMismatch(w, h, m.len(), 1));
    }
    let dist: Vec<f32> = distance_to_background(m, w, h, Outside::Background)
        .into_iter()
        .map(|d| d as f32)
        .collect();
    let min_peak = BLOB_RADIUS * w.min(h) as f32;
    if !two_peaks_in_a_component(m, &dist, w, h, min_peak)? {
        return Ok(m.to_vec());
    }
    let (blob, _) = split_at_necks(m, &dist, w, h, BLOB_NECK, min_peak)?;
    Ok(without_meeting_pixels(&blob, w, h))
}

/// The pixels of the labelling `blob` (0 = none) none of whose 8-neighbours carries another
/// label.
fn without_meeting_pixels(blob: &[u32], w: usize, h: usize) -> Vec<bool> {
    (0..w * h)
        .map(|k| {
            let (x, y) = (k % w, k / w);
            let alone = |a: usize, b: usize| [0, blob[k]].contains(&blob[b * w + a]);
            blob[k] != 0
                && (y.saturating_sub(1)..=(y + 1).min(h - 1))
                    .all(|b| (x.saturating_sub(1)..=(x + 1).min(w - 1)).all(|a| alone(a, b)))
        })
        .collect()
}

/// Whether a component of `m` holds two pixels at least `min_peak` inside that are local
/// maxima of `dist` in [`split_at_necks`]' flooding order (farther first, ties in raster
/// order): each basin starts at such a pixel, so without two in one component every
/// component floods as one blob and the split can be skipped.
fn two_peaks_in_a_component(
    m: &[bool],
    dist: &[f32],
    w: usize,
    h: usize,
    min_peak: f32,
) -> Result<bool, Error> {
    let first = |j: usize, k: usize| dist[j] > dist[k] || (dist[j] == dist[k] && j < k);
    let peak = |k: usize| {
        let (x, y) = (k % w, k / w);
        m[k] && dist[k] >= min_peak
            && (y.saturating_sub(1)..=(y + 1).min(h - 1)).all(|b| {
                (x.saturating_sub(1)..=(x + 1).min(w - 1))
                    .all(|a| !m[b * w + a] || !first(b * w + a, k))
            })
    };
    let peaks: Vec<usize> = (0..w * h).filter(|&k| peak(k)).collect();
    if peaks.len() < 2 {
        return Ok(false);
    }
    let (lab, n) = components(m, w, h)?;
    let mut seen = vec![false; n + 1];
    Ok(peaks
        .iter()
        .any(|&k| std::mem::replace(&mut seen[lab[k] as usize], true)))
}

/// The neck ratio of [`blobs_apart`]: a bridge narrower than this share of the smaller
/// blob's inscribed radius joins two objects, not two parts of one.
pub const BLOB_NECK: f32 = 0.3;

/// The least inscribed radius of a blob [`blobs_apart`] cuts off, as a share of the frame's
/// shorter side.
pub const BLOB_RADIUS: f32 = 0.05;

/// Fills holes: components of the complement (4-connected) that do not touch the border.
pub fn fill_holes(m: &[bool], w: usize, h: usize) -> Result<Vec<bool>, Error> {
    let inv: Vec<u8> = m.iter().map(|&b| u8::from(!b)).collect();
    let src = Gray::from_vec(w, h, inv).expect("mask size");
    let mut lab = Gray::new(w, h);
    let n = label(&src, &mut lab, Connectivity::Four)?;
    let lab = lab.into_vec();
    let mut touches = vec![false; n + 1];
    for x in 0..w {
        touches[lab[x] as usize] = true;
        touches[lab[(h - 1) * w + x] as usize] = true;
    }
    for y in 0..h {
        touches[lab[y * w] as usize] = true;
        touches[lab[y * w + w - 1] as usize] = true;
    }
    Ok(m.iter()
        .zip(&lab)
        .map(|(&b, &l)| b || !touches[l as usize])
        .collect())
}

/// Drops components of `m` smaller than `min_area` pixels.
pub fn remove_small(m: &[bool], w: usize, h: usize, min_area: usize) -> Result<Vec<bool>, Error> {
    let (lab, n) = components(m, w, h)?;
    let mut area = vec![0usize; n + 1];
    lab.iter().for_each(|&l| area[l as usize] += 1);
    Ok(lab
        .iter()
        .map(|&l| l != 0 && area[l as usize] >= min_area)
        .collect())
}

/// Union of the convex hulls of the 8-connected components of `m`: scikit-image's
/// `convex_hull_object(connectivity=2)`. A component's hull is taken over the midpoints of
/// its pixels' edges, and a pixel belongs to it when its centre lies inside or on the hull;
/// the arithmetic is exact (coordinates doubled to integers).
pub fn convex_hull_objects(m: &[bool], w: usize, h: usize) -> Result<Vec<bool>, Error> {
    let (lab, n) = components(m, w, h)?;
    Ok(filled_hulls(&row_extremes(&lab, n, w, h), w, h))
}

/// The union of the convex hulls of the pixel sets given by their row extremes (as
/// [`row_extremes`] gives them).
fn filled_hulls(sets: &[Vec<(usize, usize, usize)>], w: usize, h: usize) -> Vec<bool> {
    let mut out = vec![false; w * h];
    for (y, lo, hi) in sets.iter().flat_map(|rows| hull_runs(rows, w)) {
        out[y * w + lo..=y * w + hi].fill(true);
    }
    out
}

/// Per label `1..=n` of `lab` (at index `label - 1`), its leftmost and rightmost pixel in
/// each row it has pixels in, `(y, left, right)` by increasing `y`: all a convex hull needs.
fn row_extremes(lab: &[u32], n: usize, w: usize, h: usize) -> Vec<Vec<(usize, usize, usize)>> {
    let mut extremes: Vec<Vec<(usize, usize, usize)>> = vec![Vec::new(); n];
    for y in 0..h {
        let row = &lab[y * w..(y + 1) * w];
        for (x, &l) in row.iter().enumerate() {
            if l == 0 {
                continue;
            }
            match extremes[l as usize - 1].last_mut() {
                Some((ey, _, right)) if *ey == y => *right = x,
                _ => extremes[l as usize - 1].push((y, x, x)),
            }
        }
    }
    extremes
}

/// The pixel runs `(y, first x, last x)` of the convex hull of the pixels whose row
/// extremes are `rows` (as [`row_extremes`] gives them), clipped to the width `w`.
fn hull_runs(rows: &[(usize, usize, usize)], w: usize) -> Vec<(usize, usize, usize)> {
    match rows.is_empty() {
        true => Vec::new(),
        false => hull_rows(&hull_of_edge_midpoints(rows), w),
    }
}

/// Convex hulls of the 8-connected components of `m`, as [`convex_hull_objects`], except
/// that components within `join.gap` pixels of each other (Chebyshev) may share one: two
/// sets of components are joined where at least `join.min_coverage` of their joint hull's
/// outline pixels lie within `join.near` pixels of `m` and their pixels cover at most
/// `join.max_fill` of it, the best-covered pair first, the joined sets again. So the arcs of
/// one object's broken outline take one hull; two objects side by side keep theirs, as
/// their joint hull adds two edges across the background between them, or, where they are
/// so close that those edges are short, as they fill it. (Short arcs that outline a hull
/// only all together, as four quarters of a ring, stay apart: no pair of them passes; nor
/// is anything joined where more than [`MAX_LINKS`] pairs are within the gap.)
pub fn convex_hulls_joined(
    m: &[bool],
    w: usize,
    h: usize,
    join: &ArcJoin,
) -> Result<Vec<bool>, Error> {
    let (lab, n) = components(m, w, h)?;
    if n >= 1 << 24 {
        // Labels past f32's integers: no pairs can be told apart (a checkerboard of
        // single pixels over 32 megapixels); one hull per component.
        return convex_hull_objects(m, w, h);
    }
    let mut rows = row_extremes(&lab, n, w, h);
    let pairs = neighbour_pairs(&lab, n, w, h, join.gap)?;
    if pairs.is_empty() || pairs.len() > MAX_LINKS {
        return Ok(filled_hulls(&rows, w, h));
    }
    let near = grown(m, w, h, join.near)?;
    let mut area = vec![0usize; n + 1];
    lab.iter().for_each(|&l| area[l as usize] += 1);
    // The coverage of the joint hull of the sets whose roots are `a` and `b`, where it
    // passes.
    let judge = |rows: &[Vec<(usize, usize, usize)>], area: &[usize], a: usize, b: usize| {
        let joint: Vec<_> = rows[a - 1].iter().chain(&rows[b - 1]).copied().collect();
        let runs = hull_runs(&joint, w);
        let hull: usize = runs.iter().map(|&(_, lo, hi)| hi - lo + 1).sum();
        let fill = (area[a] + area[b]) as f32 / hull.max(1) as f32;
        let coverage = outline_coverage(&runs, &near, w);
        (fill <= join.max_fill && coverage >= join.min_coverage).then_some(coverage)
    };
    // Sets of labels (the root the smallest); a set's row extremes and area move to its
    // root. The linked pairs of roots keep their judgement until one of them is joined.
    let mut sets = Forest((0..=n as u32).collect());
    let mut links: Vec<(usize, usize, Option<f32>)> = (pairs.into_iter())
        .map(|(a, b)| (a, b, judge(&rows, &area, a, b)))
        .collect();
    while let Some((_, a, b)) = (links.iter())
        .filter_map(|&(x, y, c)| c.map(|c| (c, x, y)))
        .max_by(|p, q| p.0.total_cmp(&q.0))
    {
        sets.union(a as u32, b as u32);
        let moved = std::mem::take(&mut rows[b - 1]);
        rows[a - 1].extend(moved);
        area[a] += area[b];
        links = (links.into_iter())
            .map(|(x, y, c)| {
                (
                    sets.find(x as u32) as usize,
                    sets.find(y as u32) as usize,
                    c,
                )
            })
            .filter(|(x, y, _)| x != y)
            .map(|(x, y, c)| (x.min(y), x.max(y), c))
            .collect();
        links.sort_unstable_by_key(|&(x, y, _)| (x, y));
        links.dedup_by_key(|l| (l.0, l.1));
        for l in links.iter_mut().filter(|l| l.0 == a || l.1 == a) {
            l.2 = judge(&rows, &area, l.0, l.1);
        }
    }
    Ok(filled_hulls(&rows, w, h))
}

/// [`convex_hulls_joined`] joins nothing where more pairs of components than this are
/// within its gap: a mask of that many close specks is texture or noise, not the arcs of a
/// few rims, and judging every pair again after each join would grow with their square.
pub const MAX_LINKS: usize = 256;

/// How [`convex_hulls_joined`] joins components.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArcJoin {
    /// Largest gap (pixels, Chebyshev) between two components it may join.
    pub gap: usize,
    /// Distance (pixels) from the mask within which a joint hull's outline counts as
    /// covered.
    pub near: usize,
    /// Least share of the joint hull's outline covered.
    pub min_coverage: f32,
    /// Largest share of the joint hull the components' pixels may fill.
    pub max_fill: f32,
}

impl ArcJoin {
    /// The defaults for the arcs of an object's rim in a `w x h` frame, with an outline
    /// tolerance of `near` pixels: a gap of [`ARC_GAP`] of the shorter side, at least
    /// [`ARC_COVERAGE`] covered, at most [`ARC_MAX_FILL`] filled.
    pub fn rim_arcs(w: usize, h: usize, near: usize) -> Self {
        ArcJoin {
            gap: (ARC_GAP * w.min(h) as f32).round() as usize,
            near,
            min_coverage: ARC_COVERAGE,
            max_fill: ARC_MAX_FILL,
        }
    }
}

/// The gap [`ArcJoin::rim_arcs`] bridges, as a share of the frame's shorter side: an
/// object's rim seen as coherent arcs (a glass ball's, where reflection and transmission
/// cancel between them; an opaque one's, where the diffuse and specular phases do) breaks
/// over less than this.
pub const ARC_GAP: f32 = 0.125;

/// The share of a joint hull's outline [`ArcJoin::rim_arcs`] asks to lie along the mask:
/// between what the joint hulls of one rim's arcs and those of two objects side by side
/// reach on the dev frames (docs/benchmarks.md, "one hull over a rim's arcs").
pub const ARC_COVERAGE: f32 = 0.8;

/// The largest share of their joint hull [`ArcJoin::rim_arcs`] lets the components fill:
/// the arcs of a rim leave its face empty, two solid objects close together fill most of
/// the hull around them.
pub const ARC_MAX_FILL: f32 = 0.75;

/// `m` grown by `r` pixels (a square of side `2r + 1`).
fn grown(m: &[bool], w: usize, h: usize, r: usize) -> Result<Vec<bool>, Error> {
    let src = Gray::from_vec(w, h, m.iter().map(|&b| f32::from(u8::from(b))).collect())
        .expect("mask size");
    let mut dst = Gray::new(w, h);
    max_filter(&src, &mut dst, 2 * r + 1, 2 * r + 1)?;
    Ok(dst.as_slice().iter().map(|&v| v > 0.5).collect())
}

/// The pairs `(a, b)`, `a < b`, of labels `1..=n` of `lab` whose pixels come within `gap`
/// pixels (Chebyshev) of each other: the smallest and largest label in each pixel's
/// window of side `gap + 1` (labels up to 2^24, exact as `f32`).
fn neighbour_pairs(
    lab: &[u32],
    n: usize,
    w: usize,
    h: usize,
    gap: usize,
) -> Result<Vec<(usize, usize)>, Error> {
    let window_max = |f: &dyn Fn(u32) -> f32| -> Result<Vec<f32>, Error> {
        let src = Gray::from_vec(w, h, lab.iter().map(|&l| f(l)).collect()).expect("mask size");
        let mut dst = Gray::new(w, h);
        max_filter(&src, &mut dst, gap + 1, gap + 1)?;
        Ok(dst.into_vec())
    };
    let largest = window_max(&|l| l as f32)?;
    // The smallest label is `n + 1` less the largest of `n + 1 - label`.
    let smallest = window_max(&|l| {
        if l == 0 {
            0.0
        } else {
            (n + 1 - l as usize) as f32
        }
    })?;
    let mut pairs: Vec<(usize, usize)> = (0..w * h)
        .filter(|&k| smallest[k] > 0.0)
        .map(|k| (n + 1 - smallest[k] as usize, largest[k] as usize))
        .filter(|(a, b)| a < b)
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    Ok(pairs)
}

/// Share of the outline pixels of the convex region `runs` (one run per row, consecutive
/// rows, as [`hull_runs`] gives them) that are set in `near`.
fn outline_coverage(runs: &[(usize, usize, usize)], near: &[bool], w: usize) -> f32 {
    let covers = |i: Option<usize>, x: usize| {
        i.and_then(|i| runs.get(i))
            .is_some_and(|&(_, lo, hi)| (lo..=hi).contains(&x))
    };
    let (mut on, mut all) = (0usize, 0usize);
    for (i, &(y, lo, hi)) in runs.iter().enumerate() {
        for x in lo..=hi {
            if x == lo || x == hi || !covers(i.checked_sub(1), x) || !covers(Some(i + 1), x) {
                all += 1;
                on += usize::from(near[y * w + x]);
            }
        }
    }
    on as f32 / all.max(1) as f32
}

/// Convex hull (Andrew's monotone chain, counter-clockwise, collinear points dropped) of
/// the edge midpoints of the pixels `(y, left..=right)`, in doubled coordinates `(2x, 2y)`.
fn hull_of_edge_midpoints(rows: &[(usize, usize, usize)]) -> Vec<(i64, i64)> {
    let mut pts: Vec<(i64, i64)> = Vec::with_capacity(rows.len() * 8);
    for &(y, left, right) in rows {
        let y = 2 * y as i64;
        for x in [2 * left as i64, 2 * right as i64] {
            pts.extend([(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)]);
        }
    }
    pts.sort_unstable();
    pts.dedup();
    let cross = |o: (i64, i64), a: (i64, i64), b: (i64, i64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(i64, i64)> = Vec::with_capacity(pts.len() + 1);
    for pass in [
        pts.as_slice(),
        &pts.iter().rev().copied().collect::<Vec<_>>(),
    ] {
        let start = hull.len();
        for &p in pass {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// The pixel runs `(y, first x, last x)` whose centres `(2x, 2y)` lie inside or on the
/// convex polygon `hull` (doubled coordinates), clipped to the image width `w`.
fn hull_rows(hull: &[(i64, i64)], w: usize) -> Vec<(usize, usize, usize)> {
    let (y0, y1) = hull
        .iter()
        .fold((i64::MAX, i64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let mut runs = Vec::new();
    // Centre rows 2y with y0 <= 2y <= y1.
    for y in (y0 + 1).div_euclid(2).max(0)..=y1.div_euclid(2) {
        let yy = 2 * y;
        let (mut lo, mut hi) = (i64::MAX, i64::MIN);
        for (i, &a) in hull.iter().enumerate() {
            let b = hull[(i + 1) % hull.len()];
            if yy < a.1.min(b.1) || yy > a.1.max(b.1) {
                continue;
            }
            if a.1 == b.1 {
                lo = lo.min(ceil_div(a.0.min(b.0), 2));
                hi = hi.max((a.0.max(b.0)).div_euclid(2));
                continue;
            }
            // Crossing at x = a.0 + (yy − a.1)(b.0 − a.0)/(b.1 − a.1); pixel x when 2x on it.
            let (num, den) = (
                a.0 * (b.1 - a.1) + (yy - a.1) * (b.0 - a.0),
                2 * (b.1 - a.1),
            );
            let (num, den) = if den < 0 { (-num, -den) } else { (num, den) };
            lo = lo.min(ceil_div(num, den));
            hi = hi.max(num.div_euclid(den));
        }
        let hi = hi.min(w as i64 - 1);
        if lo.max(0) <= hi {
            runs.push((y as usize, lo.max(0) as usize, hi as usize));
        }
    }
    runs
}

/// `⌈a / b⌉` for `b > 0`.
fn ceil_div(a: i64, b: i64) -> i64 {
    -(-a).div_euclid(b)
}

/// Structuring-element diameter: about 1/40 of the image's smaller side, odd, at least 3.
pub fn morph_size(w: usize, h: usize) -> usize {
    ((w.min(h) / 40) | 1).max(3)
}

/// The mask pipeline: close then open ([`morph_size`]), fill holes, drop components
/// under 1/2000 of the image (at least 4 pixels).
pub fn clean(seed: &[bool], w: usize, h: usize) -> Result<Vec<bool>, Error> {
    filled_without_specks(&close_open(seed, w, h, morph_size(w, h))?, w, h)
}

/// [`clean`] with [`close_open_keeping_lines`] for the closing and opening.
pub fn clean_keeping_lines(
    seed: &[bool],
    w: usize,
    h: usize,
    min_density: f32,
) -> Result<Vec<bool>, Error> {
    let m = close_open_keeping_lines(seed, w, h, morph_size(w, h), min_density)?;
    filled_without_specks(&m, w, h)
}

/// `m` with its holes filled and without components under 1/2000 of the image (at least 4
/// pixels).
fn filled_without_specks(m: &[bool], w: usize, h: usize) -> Result<Vec<bool>, Error> {
    remove_small(&fill_holes(m, w, h)?, w, h, (w * h / 2000).max(4))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two discs of radius `r` at `x0` and `x1` on the middle row of a 64x32 mask, with a
    /// bridge `half` pixels either side of that row between them, and the brute-force
    /// Euclidean distance of each mask pixel to the nearest pixel off the mask.
    fn two_discs(x0: f32, x1: f32, r: f32, half: usize) -> (Vec<bool>, Vec<f32>) {
        let (w, h) = (64, 32);
        let m: Vec<bool> = (0..w * h)
            .map(|k| {
                let (x, y) = ((k % w) as f32, (k / w) as f32);
                let disc = |cx: f32| (x - cx).hypot(y - 16.0) <= r;
                let bridge = x >= x0 && x <= x1 && (y - 16.0).abs() <= half as f32;
                disc(x0) || disc(x1) || bridge
            })
            .collect();
        let dist = (0..w * h)
            .map(|k| {
                if !m[k] {
                    return 0.0;
                }
                let (x, y) = ((k % w) as f32, (k / w) as f32);
                (0..w * h)
                    .filter(|&j| !m[j])
                    .map(|j| ((j % w) as f32 - x).hypot((j / w) as f32 - y))
                    .fold(f32::INFINITY, f32::min)
            })
            .collect();
        (m, dist)
    }

    /// Two discs of radius 10 joined by a 3-pixel bridge are two blobs, each disc one of
    /// them; joined by a waist as wide as themselves, or overlapping, they are one.
    #[test]
    fn split_at_necks_cuts_a_bridge_not_a_waist() {
        let (w, h) = (64, 32);
        let (m, dist) = two_discs(16.0, 46.0, 10.0, 1);
        let (labels, count) = split_at_necks(&m, &dist, w, h, 0.5, 3.0).unwrap();
        assert_eq!(count, 2);
        let centre = |x: usize| labels[16 * w + x];
        assert!(centre(16) != 0 && centre(46) != 0 && centre(16) != centre(46));
        for k in (0..w * h).filter(|&k| m[k]) {
            let x = (k % w) as f32;
            if (x - 16.0).hypot((k / w) as f32 - 16.0) <= 8.0 {
                assert_eq!(labels[k], centre(16), "pixel {k} left its disc");
            }
        }
        assert!((0..w * h).all(|k| (labels[k] != 0) == m[k]));
        for (x1, half) in [(46.0, 9), (26.0, 0)] {
            let (m, dist) = two_discs(16.0, x1, 10.0, half);
            assert_eq!(
                split_at_necks(&m, &dist, w, h, 0.5, 3.0).unwrap().1,
                1,
                "{x1} {half}"
            );
        }
    }

    /// Two discs joined by a 3-pixel bridge come apart as two components, nothing lost but
    /// the pixels where they meet (the bridge's two columns either side of the cut); a disc
    /// alone stays whole.
    #[test]
    fn blobs_apart_cuts_the_bridge_and_keeps_a_disc_whole() {
        let (w, h) = (64, 32);
        let (m, _) = two_discs(16.0, 46.0, 10.0, 1);
        let apart = blobs_apart(&m, w, h).unwrap();
        assert_eq!(components(&m, w, h).unwrap().1, 1);
        assert_eq!(components(&apart, w, h).unwrap().1, 2);
        assert!((0..w * h).all(|k| !apart[k] || m[k]));
        let lost = (0..w * h).filter(|&k| m[k] && !apart[k]).count();
        assert!(lost <= 6, "{lost} pixels left out");
        let (one, _) = two_discs(16.0, 16.0, 10.0, 0);
        assert_eq!(blobs_apart(&one, w, h).unwrap(), one);
        assert!(matches!(
            blobs_apart(&one[1..], w, h),
            Err(Error::SizeMismatch(..))
        ));
        assert_eq!(blobs_apart(&[], 0, 0).unwrap(), Vec::<bool>::new());
    }

    /// Skipping the split where no component holds two peaks changes nothing: on discs
    /// alone, bridged, overlapping and touching, `blobs_apart` equals the split it skips.
    #[test]
    fn blobs_apart_equals_the_split_where_it_skips_it() {
        let (w, h) = (64, 32);
        for (x1, r, half) in [
            (46.0, 10.0, 1),
            (46.0, 10.0, 4),
            (30.0, 10.0, 0),
            (16.0, 10.0, 0),
            (40.0, 4.0, 1),
        ] {
            let (m, _) = two_discs(16.0, x1, r, half);
            let dist: Vec<f32> = distance_to_background(&m, w, h, Outside::Background)
                .into_iter()
                .map(|d| d as f32)
                .collect();
            let min_peak = BLOB_RADIUS * h as f32;
            let (blob, _) = split_at_necks(&m, &dist, w, h, BLOB_NECK, min_peak).unwrap();
            let want = without_meeting_pixels(&blob, w, h);
            assert_eq!(blobs_apart(&m, w, h).unwrap(), want, "{x1} {r} {half}");
        }
    }

    /// A distance plane of the wrong size or a non-finite distance on the mask is an
    /// error, not a panic or a silently odd split.
    #[test]
    fn split_at_necks_rejects_bad_input() {
        let (m, mut dist) = two_discs(16.0, 46.0, 10.0, 1);
        assert!(matches!(
            split_at_necks(&m, &dist[1..], 64, 32, 0.5, 3.0),
            Err(Error::SizeMismatch(..))
        ));
        dist[16 * 64 + 16] = f32::NAN;
        assert!(matches!(
            split_at_necks(&m, &dist, 64, 32, 0.5, 3.0),
            Err(Error::NonFinite)
        ));
    }

    #[test]
    fn ring_hole_is_filled_and_border_gap_is_not() {
        // 7x7: a ring around (3,3), and a notch open to the border at the top.
        let (w, h) = (7, 7);
        let mut m = vec![false; w * h];
        for y in 1..6 {
            for x in 1..6 {
                m[y * w + x] = x == 1 || x == 5 || y == 1 || y == 5;
            }
        }
        let f = fill_holes(&m, w, h).unwrap();
        assert!(f[3 * w + 3] && f[2 * w + 2]);
        assert!(!f[0] && !f[3 * w]);
    }

    #[test]
    fn hull_keeps_single_pixels_and_empty_masks() {
        assert_eq!(
            convex_hull_objects(&[false; 6], 3, 2).unwrap(),
            vec![false; 6]
        );
        let mut m = vec![false; 12];
        m[0] = true;
        m[11] = true;
        assert_eq!(convex_hull_objects(&m, 4, 3).unwrap(), m);
        assert_eq!(convex_hull_objects(&[true], 1, 1).unwrap(), vec![true]);
    }

    /// An open arc (a C) is closed into its convex disc; two separate arcs keep their own
    /// hulls, not one across the gap between them.
    #[test]
    fn hull_closes_an_open_arc_per_component() {
        let (w, h) = (40, 20);
        let mut m = vec![false; w * h];
        for t in 0..300 {
            let a = (f64::from(t) / 300.0) * 1.6 * std::f64::consts::PI + 0.3;
            for cx in [9.0, 29.0] {
                let (x, y) = (cx + 7.0 * a.cos(), 9.5 + 7.0 * a.sin());
                m[y.round() as usize * w + x.round() as usize] = true;
            }
        }
        let hull = convex_hull_objects(&m, w, h).unwrap();
        for cx in [9, 29] {
            assert!(
                hull[9 * w + cx] && hull[9 * w + cx + 6],
                "centre and the open side"
            );
        }
        assert!(!hull[9 * w + 19], "nothing between the two arcs");
        assert!(!hull[0] && !hull[w - 1]);
    }

    /// A 3-pixel-wide ring of radius 14 around `(cx, 20)` on a 96x40 mask, cut into `arcs`
    /// arcs (2 or 4) by gaps of `half_gap` degrees either side of the horizontal (and of
    /// the vertical).
    fn ring_in_arcs(m: &mut [bool], w: usize, cx: f64, arcs: u8, half_gap: f64) {
        let half = f64::from(arcs) / 2.0;
        for (k, px) in m.iter_mut().enumerate() {
            let (dx, dy) = ((k % w) as f64 - cx, (k / w) as f64 - 20.0);
            let gap = (half * dy.atan2(dx)).sin().abs() < (half * half_gap.to_radians()).sin();
            *px |= (12.5..=15.5).contains(&dx.hypot(dy)) && !gap;
        }
    }

    /// The two arcs of each of two rings (cut by 9-10 pixel gaps at the sides) take one
    /// hull per ring; the rings, side by side within the gap, keep their own (their joint
    /// hull's outline runs over the background between them); with no gap the result is
    /// [`convex_hull_objects`]. Four quarters of a ring stay apart: no pair outlines its
    /// joint hull.
    #[test]
    fn arcs_of_one_outline_take_one_hull_objects_side_by_side_do_not() {
        let (w, h) = (96, 40);
        let join = |gap| ArcJoin {
            gap,
            ..ArcJoin::rim_arcs(w, h, 2)
        };
        let mut m = vec![false; w * h];
        ring_in_arcs(&mut m, w, 24.0, 2, 20.0);
        ring_in_arcs(&mut m, w, 60.0, 2, 20.0);
        let apart = convex_hull_objects(&m, w, h).unwrap();
        assert_eq!(convex_hulls_joined(&m, w, h, &join(0)).unwrap(), apart);
        assert!(
            !apart[20 * w + 24] && !apart[20 * w + 60],
            "arcs alone leave the centres"
        );
        let joined = convex_hulls_joined(&m, w, h, &join(12)).unwrap();
        for x in [11, 24, 37, 47, 60, 73] {
            assert!(joined[20 * w + x], "x = {x}: centres and sides filled");
        }
        assert!(!joined[20 * w + 42], "nothing between the two rings");
        assert!(
            joined.iter().zip(&apart).all(|(&j, &a)| j || !a),
            "joining only adds pixels"
        );
        let mut quarters = vec![false; w * h];
        ring_in_arcs(&mut quarters, w, 24.0, 4, 12.0);
        assert_eq!(
            convex_hulls_joined(&quarters, w, h, &join(12)).unwrap(),
            convex_hull_objects(&quarters, w, h).unwrap()
        );
    }

    /// Two solid boxes 4 pixels apart outline their joint hull all but across the gap, but
    /// fill nine tenths of it: two objects, not the arcs of one; with no cap on the fill
    /// they would be joined.
    #[test]
    fn solid_objects_close_together_keep_their_hulls() {
        let (w, h) = (64, 40);
        let m: Vec<bool> = (0..w * h)
            .map(|k| {
                let (x, y) = (k % w, k / w);
                (4..36).contains(&y) && ((6..30).contains(&x) || (34..58).contains(&x))
            })
            .collect();
        let rim = ArcJoin::rim_arcs(w, h, 2);
        assert_eq!(
            convex_hulls_joined(&m, w, h, &rim).unwrap(),
            convex_hull_objects(&m, w, h).unwrap()
        );
        let uncapped = ArcJoin {
            max_fill: 1.0,
            ..rim
        };
        assert!(convex_hulls_joined(&m, w, h, &uncapped).unwrap()[20 * w + 32]);
    }

    /// A 256x256 mask of 4,096 specks (2x2 pixels, 2 apart), each pair of neighbours
    /// outlining its joint hull: more linked pairs than [`MAX_LINKS`], so one hull each.
    #[test]
    fn a_mask_of_many_close_specks_joins_nothing() {
        let (w, h) = (256, 256);
        let m: Vec<bool> = (0..w * h)
            .map(|k| (k % w) % 4 < 2 && (k / w) % 4 < 2)
            .collect();
        let joined = convex_hulls_joined(&m, w, h, &ArcJoin::rim_arcs(w, h, 2)).unwrap();
        assert_eq!(joined, convex_hull_objects(&m, w, h).unwrap());
        assert!(
            !joined[2 * w + 2],
            "the spaces between the specks stay empty"
        );
    }

    /// Marsaglia's xorshift64 from `state` (non-zero): pseudo-random test masks.
    fn xorshift(mut state: u64) -> impl FnMut() -> u64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        }
    }

    /// The run-distance closing-opening equals the grey-scale one exactly, on
    /// pseudo-random masks of several densities, sizes below and above the element, odd
    /// and even diameters, up to the widest the byte distances take.
    #[test]
    fn close_open_equals_the_grey_scale_operators() {
        let mut next = xorshift(0x2545_f491_4f6c_dd1d);
        for (w, h, k) in [
            (1, 1, 3),
            (5, 3, 7),
            (40, 31, 5),
            (64, 48, 9),
            (33, 70, 8),
            (90, 20, 25),
        ] {
            for density in [5u64, 30, 50, 80] {
                let m: Vec<bool> = (0..w * h).map(|_| next() % 100 < density).collect();
                assert_eq!(
                    close_open(&m, w, h, k).unwrap(),
                    grey_close_open(&m, w, h, k).unwrap(),
                    "{w}x{h}, k = {k}, density {density}"
                );
            }
        }
    }

    /// A blob with a dashed line (3 pixels high, dashes of 6 with gaps of 2) leading right
    /// from it, a chain of 4x2 specks 4 pixels apart leading down from it, and a dashed line
    /// on its own: the closing (9) joins each into one band that the opening drops.
    fn blob_with_a_line_and_a_chain() -> (Vec<bool>, usize, usize) {
        let (w, h) = (96, 72);
        let m = (0..w * h)
            .map(|k| {
                let (x, y) = (k % w, k / w);
                let blob = (x as f32 - 20.0).hypot(y as f32 - 20.0) <= 12.0;
                let dashes = |x: usize| x % 8 < 6;
                let line = (19..22).contains(&y) && (30..90).contains(&x) && dashes(x);
                let chain = (18..22).contains(&x) && (30..70).contains(&y) && y % 6 < 2;
                let lone = (60..63).contains(&y) && (40..90).contains(&x) && dashes(x);
                blob || line || chain || lone
            })
            .collect();
        (m, w, h)
    }

    #[test]
    fn dashed_line_from_a_blob_stays_a_chain_of_specks_goes() {
        let (m, w, h) = blob_with_a_line_and_a_chain();
        let at = |out: &[bool], x: usize, y: usize| out[y * w + x];
        let (line, chain, lone) = ((60, 20), (19, 50), (60, 61));
        let plain = close_open(&m, w, h, 9).unwrap();
        assert!(at(&plain, 20, 20) && !at(&plain, line.0, line.1));
        let kept = close_open_keeping_lines(&m, w, h, 9, 0.7).unwrap();
        assert!(
            at(&kept, 20, 20) && at(&kept, line.0, line.1),
            "the line is dropped"
        );
        assert!(!at(&kept, chain.0, chain.1), "the chain is kept");
        assert!(!at(&kept, lone.0, lone.1), "the line on its own is kept");
        let all = close_open_keeping_lines(&m, w, h, 9, 0.0).unwrap();
        assert!(at(&all, chain.0, chain.1) && !at(&all, lone.0, lone.1));
    }

    /// No thin part is covered beyond all its pixels: nothing is kept that the opening drops.
    #[test]
    fn keeping_lines_past_full_density_is_close_open() {
        let mut next = xorshift(0x9e37_79b9_7f4a_7c15);
        for (w, h, k) in [(1, 1, 3), (40, 31, 5), (64, 48, 9)] {
            for density in [5u64, 30, 50, 80] {
                let m: Vec<bool> = (0..w * h).map(|_| next() % 100 < density).collect();
                assert_eq!(
                    close_open_keeping_lines(&m, w, h, k, 1.5).unwrap(),
                    close_open(&m, w, h, k).unwrap(),
                    "{w}x{h}, k = {k}, density {density}"
                );
            }
        }
    }

    #[test]
    fn small_components_go() {
        let (w, h) = (5, 1);
        let m = [true, false, true, true, true];
        assert_eq!(
            remove_small(&m, w, h, 2).unwrap(),
            [false, false, true, true, true]
        );
    }
}
