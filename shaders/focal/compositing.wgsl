#define_import_path focal::compositing

// Front-to-back "under" compositing of a colour with opacity α (premultiplied result):
// C += (1 − A)·α·c, A += (1 − A)·α.

fn composite(acc: vec4<f32>, c: vec3<f32>, alpha: f32) -> vec4<f32> {
    let w = (1.0 - acc.a) * alpha;
    return acc + vec4(c * w, w);
}
