//! Temporary: profile a drag of Glasses point 64 through RenderCache.
use gradmesh::render::{self, RenderCache, RenderOptions, View};
use std::time::Instant;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let file = args
        .get(1)
        .cloned()
        .unwrap_or("../shared/realdata/gradientmeshimproved-off/Glasses.off".into());
    let point: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(64);
    let steps: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(200);
    let doc = gradmesh::formats::read_path(std::path::Path::new(&file)).unwrap();
    let bounds = View::fit(&doc, 0.02);
    let height = (1024.0 * bounds.height() / bounds.width()).round() as u32;
    let opts = RenderOptions::new(1024, height, bounds);
    let mut cache = RenderCache::new();
    let mut pixels = vec![0u8; 4 * 1024 * height as usize];
    render::render_document_into_cached(&doc, &opts, &mut cache, &mut pixels).unwrap();
    let mut edited = doc.clone();
    let mut times = vec![];
    let (mut prep, mut draw) = (vec![], vec![]);
    let mut last = None;
    for step in 0..steps {
        let dx = 3.0 * ((step % 8) as f64 / 4.0 - 1.0);
        edited.layers[0].points[point].position.x = doc.layers[0].points[point].position.x + dx;
        edited.layers[0].points[point].position.y =
            doc.layers[0].points[point].position.y + dx / 2.0;
        let t = Instant::now();
        let info =
            render::render_document_into_cached(&edited, &opts, &mut cache, &mut pixels).unwrap();
        times.push(t.elapsed().as_secs_f64() * 1e3);
        prep.push(info.timings.prepare.as_secs_f64() * 1e3);
        draw.push(info.timings.draw.as_secs_f64() * 1e3);
        last = Some(info);
    }
    let med = |v: &mut Vec<f64>| {
        v.sort_by(|a, b| a.partial_cmp(b).unwrap());
        (v[v.len() / 2], v[v.len() * 95 / 100])
    };
    let info = last.unwrap();
    let l = &info.layers[0];
    println!("total {:?} prepare {:?} draw {:?}; quads {} triangles {} reused_faces {} level {} drawn_pixels {} lt {:?}",
        med(&mut times), med(&mut prep), med(&mut draw), l.quads, l.triangles, l.reused_faces, l.level, info.drawn_pixels, l.timings);
}
