//! The 2-node scene of the generated grillage bodies (`python fixtures/generate.py
//! --large`, about 45 s: fixtures/large.fxb, large_free.fxb and their /NODE decks), found
//! from the deck alone so that a benchmark needs nothing the generator does not write
//! beside the body: the tip (the middle of the free edge, where the blocked body's
//! static modes are attached) and the far corner (the largest ID). Both bodies number
//! the same grid the same way, so the blocked body's deck names the nodes of both.

use std::path::Path;

use fxbody::fxb::coords;

/// The tip and corner node IDs of the grillage whose blocked body's deck is `deck`
/// (fixtures/large.nodes.rad): the tip has the largest X and, among those, the Y nearest
/// the middle of the Y range.
pub fn two_nodes(deck: &Path) -> Vec<i64> {
    let xyz = coords::read_coords(deck).expect("the grillage's /NODE deck");
    let x_max = xyz.iter().map(|(_, p)| p[0]).fold(f64::MIN, f64::max);
    let (y_lo, y_hi) = xyz.iter().fold((f64::MAX, f64::MIN), |(lo, hi), (_, p)| {
        (lo.min(p[1]), hi.max(p[1]))
    });
    let y_mid = 0.5 * (y_lo + y_hi);
    let tip = xyz
        .iter()
        .filter(|(_, p)| p[0] == x_max)
        .min_by(|a, b| (a.1[1] - y_mid).abs().total_cmp(&(b.1[1] - y_mid).abs()))
        .map(|(id, _)| *id)
        .expect("a node at the largest X");
    let corner = xyz.iter().map(|(id, _)| *id).max().expect("nodes");
    vec![tip, corner]
}
