use pleat::lowpoly::{offset_surface, OffsetDistance, OffsetParams};
use pleat::mesh::TriMesh;

#[test]
fn smoke_cube() {
    let p: Vec<[f64; 3]> = (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect();
    let t = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    let m = TriMesh::new(p, t).unwrap();
    for np in [20.0, 50.0] {
        for features in [false, true] {
            let params = OffsetParams {
                distance: OffsetDistance::ScreenSize(np),
                features,
                ..Default::default()
            };
            let (out, stats) = offset_surface(&m, &params).unwrap();
            eprintln!(
                "np {np} features {features}: {} v {} t; {:?} {:?} {:?} {:?}",
                out.vertex_count(),
                out.triangle_count(),
                stats.verified,
                stats.metrics,
                stats.counts,
                stats.stages
            );
        }
    }
}
