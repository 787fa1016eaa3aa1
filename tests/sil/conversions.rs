//! One sample's conversions through the sample task's frame builder (`app::FrameBuilder`,
//! what `src/firmware/sample_task.rs` runs per sample) into the sample path: a clipped
//! conversion is flagged, counted on the status line and held out of the residuals; a
//! glitch on the encoder's lines is rejected, counted, and not taken as speed.

use super::*;
use drive_monitor::acquisition::{CHANNELS, HALF_LEN, OVERSAMPLING};
use drive_monitor::app::FrameBuilder;
use drive_monitor::motor_source;

/// The ADCs' sequences and the latched counts of one sample: each of its eight triggers
/// converts the frame's codes, the count advancing evenly from the previous sample's.
fn conversions(
    raw: &RawFrame,
    previous_count: u16,
) -> ([u16; HALF_LEN], [u16; HALF_LEN], [u16; OVERSAMPLING]) {
    let (mut v, mut i) = ([0u16; HALF_LEN], [0u16; HALF_LEN]);
    for (k, (v, i)) in v.iter_mut().zip(i.iter_mut()).enumerate() {
        *v = raw.v[k % CHANNELS].0;
        *i = raw.i[k % CHANNELS].0;
    }
    let step = raw.encoder_count.wrapping_sub(previous_count) as i16;
    let latched = std::array::from_fn(|t| {
        previous_count.wrapping_add((i32::from(step) * (t as i32 + 1) / OVERSAMPLING as i32) as u16)
    });
    (v, i, latched)
}

/// Runs `frames` through a frame builder with the built-in record's ranges and encoder
/// check into the sample path; `edit(k, v, i, latched)` may change sample `k`'s
/// conversions and counts. The sample path at the end and the largest speed it read after
/// 1.5 s [rad/s].
fn run(
    frames: &[RawFrame],
    mut edit: impl FnMut(usize, &mut [u16; HALF_LEN], &mut [u16; HALF_LEN], &mut [u16; OVERSAMPLING]),
) -> (SamplePath, f32, bool) {
    let rec = motor_source::default_record();
    let setup = motor_source::encoder_setup(&rec, FS);
    let mut builder = FrameBuilder::new(
        FS,
        50.0,
        motor_source::linear_ranges(&rec),
        setup.max_step_per_trigger,
    );
    let mut path = SamplePath::for_board(FS).unwrap();
    let mut previous = frames[0].encoder_count;
    let (mut top_speed, mut speed_flag) = (0.0f32, false);
    for (k, raw) in frames.iter().enumerate() {
        let (mut v, mut i, mut latched) = conversions(raw, previous);
        previous = raw.encoder_count;
        edit(k, &mut v, &mut i, &mut latched);
        let frame = builder.frame(&v, &i, &latched);
        path.on_frame(&frame);
        if k > 15_000 {
            let o = path.monitor().output();
            top_speed = top_speed.max(o.speed_rad_s);
            speed_flag |= o.sensor_fault.speed;
        }
    }
    (path, top_speed, speed_flag)
}

/// An inrush-like peak clipped on two of one sample's eight current conversions: its mean
/// (and the filtered code) is far from the rail, the per-conversion check flags it; the
/// sample and the 16 after it (the filter's memory) are counted, the core holds the block
/// out (the filters not fed, the settling time started again: not evaluating 0.2 s later)
/// and names no sensor. The run without the peak counts only the start's inrush, which
/// clips the 10 A front end too, and names nothing either.
#[test]
fn a_clipped_conversion_is_flagged_counted_and_held_out() {
    let frames = steady_frames(2.0);
    const AT: usize = 18_000;
    let (path, _, _) = run(&frames, |k, _, i, _| {
        if k == AT {
            i[CHANNELS * 3] = 4095;
            i[CHANNELS * 4] = 4095;
        }
    });
    let (clean, _, _) = run(&frames, |_, _, _, _| {});
    // The start's inrush clips the 10 A front end in both runs; the peak adds its 17.
    assert!(clean.status().clipped > 0);
    assert_eq!(path.status().clipped - clean.status().clipped, 17);
    assert_eq!(path.status().clipped_current, path.status().clipped);
    // Held out: the block with the clip was discarded and the lamps wait for the settling
    // time; the clean run evaluates by then.
    assert!(clean.monitor().output().evaluating);
    assert!(!path.monitor().output().evaluating);
    // No sensor named, in either run.
    for p in [&path, &clean] {
        assert!(!p.monitor().output().sensor_fault.any());
        assert!(!p.status().sensor_fault.any());
    }
}

/// A spike of +300 counts on one latched count, and later edges lost for good (-200 on
/// every count from then on): rejected (two and one), counted on the status line, and the
/// speed reads the shaft's (no speed sensor flagged, no spike in the speed).
#[test]
fn an_encoder_glitch_is_rejected_counted_and_not_taken_as_speed() {
    let frames = steady_frames(2.5);
    let (path, top, flagged) = run(&frames, |k, _, _, latched| {
        if k == 18_000 {
            latched[5] = latched[5].wrapping_add(300);
        }
        if k >= 21_000 {
            for c in latched.iter_mut() {
                *c = c.wrapping_sub(200);
            }
        }
    });
    let (clean, clean_top, clean_flagged) = run(&frames, |_, _, _, _| {});
    assert_eq!(clean.status().encoder_rejects, 0);
    assert!(!clean_flagged);
    assert_eq!(path.status().encoder_rejects, 3);
    assert!(!flagged, "the speed sensor flagged");
    assert!(
        (top - clean_top).abs() < 0.5,
        "{top} against {clean_top} rad/s"
    );
}

/// A sample's latched counts, `step` counts a trigger on from `count`.
fn moving(count: &mut u16, step: u16) -> [u16; OVERSAMPLING] {
    std::array::from_fn(|_| {
        *count = count.wrapping_add(step);
        *count
    })
}

/// After a gap in the triggers (a recovery, a paused acquisition) the shaft may have moved
/// any distance: with the builder restarted the first count after it is no glitch (without,
/// one reject). A dropped sample's counts still go through the check: the next sample's
/// first step is one trigger long, not nine, and no glitch either (without, one reject).
#[test]
fn a_gap_restarts_the_encoder_check_and_a_dropped_samples_counts_go_through_it() {
    let rec = motor_source::default_record();
    let max = motor_source::encoder_setup(&rec, FS).max_step_per_trigger;
    let step = (max / 2).max(1);
    assert!(
        9 * step > max,
        "nine triggers' motion is beyond one trigger's largest step"
    );
    let mid = [2048u16; HALF_LEN];
    for handled in [true, false] {
        let new = || FrameBuilder::new(FS, 50.0, motor_source::linear_ranges(&rec), max);
        let want = u8::from(!handled);
        // Four frames of steady motion, none rejected: the builder and the count after them.
        let settled = || {
            let (mut builder, mut count) = (new(), 0u16);
            for _ in 0..4 {
                assert_eq!(
                    builder
                        .frame(&mid, &mid, &moving(&mut count, step))
                        .encoder_rejects,
                    0
                );
            }
            (builder, count)
        };
        // The gap: 5 000 counts on.
        let (mut builder, mut count) = settled();
        count = count.wrapping_add(5_000);
        if handled {
            builder.restart();
        }
        let after = builder.frame(&mid, &mid, &moving(&mut count, step));
        assert_eq!(after.encoder_rejects, want, "restarted {handled}");
        // A dropped sample.
        let (mut builder, mut count) = settled();
        let dropped = moving(&mut count, step);
        if handled {
            builder.skip(&dropped);
        }
        let after = builder.frame(&mid, &mid, &moving(&mut count, step));
        assert_eq!(after.encoder_rejects, want, "skipped {handled}");
    }
}
