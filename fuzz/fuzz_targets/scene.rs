//! The scene parser, its checks, its animation's frames and a turntable on arbitrary
//! text: a scene may be refused with an error naming the problem; nothing may panic.
//! Seed the corpus from `examples/*.ron`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(scene) = focal::scene::SceneFile::parse(text, "fuzz") else { return };
    if let Some(a) = &scene.animation {
        let _ = focal::scene::movie::animation_frames(a, &scene, "fuzz");
    }
    let _ = focal::scene::movie::turntable(scene, 3, 30.0, 20.0, false, 1.0);
});
