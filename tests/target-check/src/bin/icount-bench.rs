//! thumbv7em program: instruction counts of estimator-core's per-sample and per-tooth work,
//! for QEMU with `-icount shift=0` (see `target_check::bench` for the method).
//!
//! Runs the `Monitor` (`MonitorConfig::default()` at the trace's rate, a spindle lag of 0.5
//! ms allowed for) over the trace blob
//! embedded at build time (`TRACE_BIN`, see build.rs; the built-in one is too short for
//! figures) and times every `Monitor::process` call, then the estimator alone on the
//! filtered inputs of each tooth that reached it (default solver, and the exact inversion
//! for reference), then the libm functions and model pieces the per-tooth step is made of.
//! Prints `calib`/`stat`/`info` lines in the usual frame; `tests/icount_bench.rs` builds,
//! runs and tabulates them.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod target {
    use core::fmt::{self, Write};
    use core::hint::black_box;
    use core::sync::atomic::{compiler_fence, Ordering::SeqCst};
    use cortex_m::peripheral::syst::SystClkSource;
    use cortex_m::peripheral::SYST;
    use cortex_m_rt::entry;
    use estimator_core::alarm::{AlarmOutput, AlarmState, Alarms};
    use estimator_core::drive::{FeedDrive, SpindleModel};
    use estimator_core::estimator::{EstimatorConfig, Measured, Method, Solver};
    use estimator_core::forward::Operating;
    use estimator_core::invert::{invert, Ratio};
    use estimator_core::monitor::{Monitor, MonitorState, Sample, ToothRecord};
    use estimator_core::probe::{Probe, Stage};
    use estimator_core::{
        average_forces, Engagement, MachineConfig, MillingMode, Pipeline, PipelineState, Tool,
        TABLE2,
    };
    use target_check::bench::{ticks_between, Stat, SYST_MASK};
    use target_check::semihosting::{eprint, exit, Buffered};
    use target_check::{replay_config, replay_monitor, ReplayError, BEGIN, END_PREFIX};
    // Linked for their side effects: critical-section implementation and panic handler.
    use {cortex_m as _, panic_semihosting as _};

    /// The trace, copied to OUT_DIR by build.rs.
    static TRACE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/trace.bin"));

    /// Scatter passed to the estimator when timed alone [N] (its value does not change
    /// the path taken).
    const SIGMA_N: [f32; 2] = [0.5, 0.5];

    /// Stack painting pattern.
    const PAINT: u32 = 0xA5A5_A5A5;

    #[inline(always)]
    fn now() -> u32 {
        SYST::get_current()
    }

    /// Times `$e` in SysTick ticks: `(ticks, value)`. The fences keep the compiler from
    /// moving memory accesses across the reads; `black_box` on a reference to the result
    /// keeps the work inside without copying the result (callers also pass their inputs
    /// through `black_box`).
    macro_rules! timed {
        ($e:expr) => {{
            compiler_fence(SeqCst);
            let t0 = now();
            compiler_fence(SeqCst);
            let r = $e;
            black_box(&r);
            compiler_fence(SeqCst);
            let t1 = now();
            compiler_fence(SeqCst);
            (ticks_between(t0, t1), r)
        }};
    }

    /// `turns` turns of a two-instruction loop (`subs; bne`): `2 * turns` instructions.
    #[inline(always)]
    fn spin(turns: u32) {
        // Note(unsafe): a register-only countdown loop; touches no memory and no stack.
        #[allow(unsafe_code)]
        unsafe {
            core::arch::asm!(
                "2:",
                "subs {0}, {0}, #1",
                "bne 2b",
                inout(reg) turns => _,
                options(nomem, nostack),
            );
        }
    }

    // Linker symbols of cortex-m-rt: end of static RAM, top of the stack.
    extern "C" {
        static __sheap: u32;
        static _stack_start: u32;
    }

    /// `(lowest free address, top of stack)`.
    fn stack_bounds() -> (usize, usize) {
        // Only the addresses of the linker symbols are taken (safe), never their values.
        (
            core::ptr::addr_of!(__sheap) as usize,
            core::ptr::addr_of!(_stack_start) as usize,
        )
    }

    /// Fills the unused stack (up to 256 bytes below the current SP) with [`PAINT`].
    #[inline(never)]
    fn paint_stack() {
        let (lo, _) = stack_bounds();
        let sp = cortex_m::register::msp::read() as usize;
        let mut a = lo;
        while a + 4 <= sp.saturating_sub(256) {
            // Note(unsafe): `lo..sp - 256` is RAM between the statics and the live stack,
            // owned by nobody (no heap); word-aligned (`__sheap` is 4-aligned).
            #[allow(unsafe_code)]
            unsafe {
                core::ptr::write_volatile(a as *mut u32, PAINT);
            }
            a += 4;
        }
    }

    /// Deepest stack use since [`paint_stack`] [bytes].
    fn stack_peak() -> usize {
        let (lo, top) = stack_bounds();
        let mut a = lo;
        // Note(unsafe): reads the same painted words back.
        #[allow(unsafe_code)]
        while a < top && unsafe { core::ptr::read_volatile(a as *const u32) } == PAINT {
            a += 4;
        }
        top - a
    }

    /// Statistics of the trace runs (each a [`Stat`] in ticks), by report name.
    struct Stats {
        overhead: Stat,
        // `Monitor::process`.
        sample: Stat,
        tooth: Stat,
        tooth_est: Stat,
        tooth_est_poly: Stat,
        tooth_est_inv: Stat,
        tooth_flagged: Stat,
        // The estimator alone on the monitor's filtered inputs.
        est_poly: Stat,
        est_auto_inv: Stat,
        est_inversion: Stat,
        // `Alarms::process` alone on the monitor's records.
        alarm: Stat,
        alarm_est_poly: Stat,
        alarm_flagged: Stat,
        alarm_wear: Stat,
        // `Pipeline::process`.
        pipe_sample: Stat,
        pipe_tooth: Stat,
        pipe_tooth_poly: Stat,
        pipe_tooth_inv: Stat,
        pipe_tooth_flagged: Stat,
        // `Pipeline::process_probed` on teeth estimated by the polynomial: the whole call,
        // each stage (time since the previous mark), and the return after the last mark.
        probed_tooth_poly: Stat,
        stage: [Stat; Stage::COUNT],
        stage_return: Stat,
        // The same for teeth flagged before the estimator (stages they pass only).
        probed_tooth_flagged: Stat,
        stage_flagged: [Stat; Stage::COUNT],
        stage_flagged_return: Stat,
    }

    impl Default for Stats {
        fn default() -> Self {
            let z = Stat::default();
            Stats {
                overhead: z,
                sample: z,
                tooth: z,
                tooth_est: z,
                tooth_est_poly: z,
                tooth_est_inv: z,
                tooth_flagged: z,
                est_poly: z,
                est_auto_inv: z,
                est_inversion: z,
                alarm: z,
                alarm_est_poly: z,
                alarm_flagged: z,
                alarm_wear: z,
                pipe_sample: z,
                pipe_tooth: z,
                pipe_tooth_poly: z,
                pipe_tooth_inv: z,
                pipe_tooth_flagged: z,
                probed_tooth_poly: z,
                stage: [z; Stage::COUNT],
                stage_return: z,
                probed_tooth_flagged: z,
                stage_flagged: [z; Stage::COUNT],
                stage_flagged_return: z,
            }
        }
    }

    /// Counts from the trace run.
    #[derive(Default)]
    struct Counts {
        samples: u32,
        records: u32,
        valid: u32,
        estimated: u32,
        poly: u32,
        inversion: u32,
        rr_mismatch: u32,
        pipeline_mismatch: u32,
        alarm_mismatch: u32,
        probed_mismatch: u32,
        alarm_events: u32,
        wear_updates: u32,
    }

    /// SysTick at the end of each stage of one probed call.
    #[derive(Clone, Copy)]
    struct Marks {
        at: [u32; Stage::COUNT],
        /// Bit `s`: stage `s` was marked.
        seen: u32,
    }

    impl Marks {
        const NONE: Marks = Marks {
            at: [0; Stage::COUNT],
            seen: 0,
        };

        /// Adds the time of each marked stage since the previous mark (the first since
        /// `t0`) to `stats`, and the time from the last mark to `t1` to `ret`.
        fn add_to(&self, t0: u32, t1: u32, stats: &mut [Stat; Stage::COUNT], ret: &mut Stat) {
            let mut prev = t0;
            for (k, stat) in stats.iter_mut().enumerate() {
                if self.seen & (1 << k) != 0 {
                    let t = self.at.get(k).copied().unwrap_or(prev);
                    stat.add(ticks_between(prev, t));
                    prev = t;
                }
            }
            ret.add(ticks_between(prev, t1));
        }
    }

    impl Probe for Marks {
        #[inline(always)]
        fn mark(&mut self, stage: Stage) {
            compiler_fence(SeqCst);
            let t = now();
            compiler_fence(SeqCst);
            if let Some(slot) = self.at.get_mut(stage as usize) {
                *slot = t;
            }
            self.seen |= 1 << stage as u32;
        }
    }

    fn calibrate(w: &mut impl Write, st: &mut Stats) -> fmt::Result {
        for _ in 0..1000 {
            let (t, ()) = timed!(());
            st.overhead.add(t);
        }
        for turns in [1_000u32, 100_000, 2_000_000] {
            let (t, ()) = timed!(spin(black_box(turns)));
            writeln!(w, "calib {turns} {} {t}", 2 * turns as u64)?;
        }
        Ok(())
    }

    /// The replay's monitor at the trace's sample rate, allowing for a spindle current
    /// loop's lag of 0.5 ms as a calibrated machine does (the trace has none: what is
    /// measured is its cost).
    fn monitor_config(sample_rate_hz: f32) -> estimator_core::MonitorConfig {
        estimator_core::MonitorConfig {
            spindle_lag_s: 0.0005,
            ..replay_config(sample_rate_hz)
        }
    }

    /// `MachineConfig::default()` with that monitor.
    fn pipeline(sample_rate_hz: f32) -> Result<Pipeline, ReplayError> {
        MachineConfig {
            monitor: monitor_config(sample_rate_hz),
            ..MachineConfig::default()
        }
        .build()
        .map_err(ReplayError::Config)
    }

    // The per-sample calls are timed inside these non-inlined functions, the result bound
    // to a fresh local (the calls build it in place there) and handed back after the
    // second SysTick read. (Timed in the loop body, the result going to a variable that
    // `black_box` or a comparison had seen in the previous turn, the compiler builds it
    // aside and copies it: 168 bytes through `memcpy` for the pipeline, a cost of the
    // measurement, not of the code measured.)

    /// `monitor.process(st, s)` and its ticks.
    #[inline(never)]
    fn time_monitor(
        monitor: &Monitor,
        st: &mut MonitorState,
        s: &Sample,
    ) -> (u32, Option<ToothRecord>) {
        compiler_fence(SeqCst);
        let t0 = now();
        compiler_fence(SeqCst);
        let r = monitor.process(st, s);
        compiler_fence(SeqCst);
        let t1 = now();
        compiler_fence(SeqCst);
        (ticks_between(t0, t1), r)
    }

    /// `pipe.process(st, s)` and its ticks.
    #[inline(never)]
    fn time_pipeline(
        pipe: &Pipeline,
        st: &mut PipelineState,
        s: &Sample,
    ) -> (u32, Option<(ToothRecord, AlarmOutput)>) {
        compiler_fence(SeqCst);
        let t0 = now();
        compiler_fence(SeqCst);
        let r = pipe.process(st, s);
        compiler_fence(SeqCst);
        let t1 = now();
        compiler_fence(SeqCst);
        (ticks_between(t0, t1), r)
    }

    /// `pipe.process_probed(st, s, marks)` and SysTick before and after.
    #[inline(never)]
    fn time_probed(
        pipe: &Pipeline,
        st: &mut PipelineState,
        s: &Sample,
        marks: &mut Marks,
    ) -> (u32, u32, Option<(ToothRecord, AlarmOutput)>) {
        compiler_fence(SeqCst);
        let t0 = now();
        compiler_fence(SeqCst);
        let r = pipe.process_probed(st, s, marks);
        compiler_fence(SeqCst);
        let t1 = now();
        compiler_fence(SeqCst);
        (t0, t1, r)
    }

    /// `alarms.process(st, rec)` and its ticks.
    #[inline(never)]
    fn time_alarms(alarms: &Alarms, st: &mut AlarmState, rec: &ToothRecord) -> (u32, AlarmOutput) {
        compiler_fence(SeqCst);
        let t0 = now();
        compiler_fence(SeqCst);
        let r = alarms.process(st, rec);
        compiler_fence(SeqCst);
        let t1 = now();
        compiler_fence(SeqCst);
        (ticks_between(t0, t1), r)
    }

    /// Runs the trace through, in lockstep, the `Monitor`, the `Alarms` fed with its records,
    /// the `Pipeline` and the probed `Pipeline`, timing each call, and checks that they
    /// agree bit for bit.
    fn run_trace(
        monitor: &Monitor,
        trace: &target_check::tms1::Tms1<'_>,
        st: &mut Stats,
    ) -> Result<Counts, ReplayError> {
        let auto = *monitor.estimator();
        let inversion = EstimatorConfig {
            solver: Solver::Inversion,
            ..*auto.config()
        }
        .build()
        .map_err(ReplayError::Config)?;
        let pipe = pipeline(trace.sample_rate_hz())?;
        let alarms = *pipe.alarms();
        let mut state = MonitorState::default();
        let mut alarm_state = AlarmState::default();
        let mut pipe_state = PipelineState::default();
        let mut probed_state = PipelineState::default();
        let mut c = Counts::default();
        let mut tripped = false;
        for s in trace.samples() {
            c.samples += 1;
            let (t, rec) = time_monitor(monitor, &mut state, &s);
            let (tp, out) = time_pipeline(&pipe, &mut pipe_state, &s);
            let mut marks = Marks::NONE;
            let (t0, t1, probed) = time_probed(&pipe, &mut probed_state, &s, &mut marks);
            // A drop trip inside a period latches the pipeline's output between records:
            // the alarms fed records alone never see it, and are compared up to it.
            if out.is_none() && pipe_state.alarms.output_latched() && !alarm_state.output_latched()
            {
                tripped = true;
            }
            let Some(rec) = rec else {
                st.sample.add(t);
                st.pipe_sample.add(tp);
                c.pipeline_mismatch += out.is_some() as u32;
                c.probed_mismatch += probed.is_some() as u32;
                continue;
            };
            c.records += 1;
            st.tooth.add(t);
            st.pipe_tooth.add(tp);
            c.valid += rec.status.is_valid() as u32;
            let words = rec.to_words();
            let Some((pipe_rec, pipe_out)) = out else {
                c.pipeline_mismatch += 1;
                continue;
            };
            c.pipeline_mismatch += (pipe_rec.to_words() != words) as u32;
            match &probed {
                Some((r, o)) => {
                    c.probed_mismatch += (r.to_words() != words || *o != pipe_out) as u32;
                }
                None => c.probed_mismatch += 1,
            }
            c.alarm_events += pipe_out.event.is_some() as u32;
            // The alarms alone, on the monitor's record.
            let (ta, alarm_out) = time_alarms(&alarms, &mut alarm_state, &rec);
            c.alarm_mismatch += (!tripped && alarm_out != pipe_out) as u32;
            st.alarm.add(ta);
            let wear_update = rec.status.is_valid() && rec.tooth == 0;
            if wear_update {
                c.wear_updates += 1;
                st.alarm_wear.add(ta);
            }
            match rec.method {
                Method::None => {
                    st.tooth_flagged.add(t);
                    st.pipe_tooth_flagged.add(tp);
                    st.alarm_flagged.add(ta);
                    st.probed_tooth_flagged.add(ticks_between(t0, t1));
                    marks.add_to(t0, t1, &mut st.stage_flagged, &mut st.stage_flagged_return);
                    continue;
                }
                Method::Polynomial => {
                    st.tooth_est_poly.add(t);
                    st.pipe_tooth_poly.add(tp);
                    st.alarm_est_poly.add(ta);
                    st.probed_tooth_poly.add(ticks_between(t0, t1));
                    marks.add_to(t0, t1, &mut st.stage, &mut st.stage_return);
                }
                _ => {
                    st.tooth_est_inv.add(t);
                    st.pipe_tooth_inv.add(tp);
                }
            }
            c.estimated += 1;
            st.tooth_est.add(t);
            // The estimator alone, on the inputs the monitor gave it.
            let m = Measured::Motor {
                fx_n: rec.fx_filt_n,
                ft_n: rec.f2_filt_n,
            };
            let tc = rec.tc_filt_mm;
            let (t, e) = timed!(auto.estimate_with_scatter(black_box(tc), black_box(m), SIGMA_N));
            match e.method {
                Method::Polynomial => {
                    c.poly += 1;
                    st.est_poly.add(t);
                }
                _ => {
                    c.inversion += 1;
                    st.est_auto_inv.add(t);
                }
            }
            if rec.status.is_valid() && e.rr.to_bits() != rec.rr.to_bits() {
                c.rr_mismatch += 1;
            }
            let (t, _) =
                timed!(inversion.estimate_with_scatter(black_box(tc), black_box(m), SIGMA_N));
            st.est_inversion.add(t);
        }
        Ok(c)
    }

    /// The pieces of the per-tooth step, on a sweep of typical down-milling cuts.
    fn pieces(w: &mut impl Write) -> fmt::Result {
        const N: usize = 64;
        let tc = 0.15f32;
        let mut s = [Stat::default(); 19];
        let feed = FeedDrive::default();
        let spindle = SpindleModel::default();
        let poly = estimator_core::fxt_poly::ALL
            .iter()
            .find(|p| p.fits(&TABLE2, MillingMode::Down));
        for k in 0..N {
            let x = k as f32 / (N - 1) as f32;
            let rr = 0.15 + 1.8 * x;
            let f = average_forces(
                &Tool::PAPER,
                &TABLE2,
                MillingMode::Down,
                Engagement {
                    rr,
                    ra: 1.0,
                    tc_mm: tc,
                },
            );
            let ratio = f.fx_n / f.ft_n;
            let t_a = 0.03 + 0.2 * x;
            let mut i = 0;
            let mut add = |t: u32| {
                s[i].add(t);
                i += 1;
            };
            add(timed!(libm::powf(black_box(t_a), black_box(-0.4362))).0);
            add(timed!(libm::logf(black_box(0.05 + 0.4 * x))).0);
            add(timed!(libm::expf(black_box(-1.5 - 2.0 * x))).0);
            add(timed!(libm::acosf(black_box(1.0 - rr))).0);
            add(timed!(libm::sinf(black_box(0.4 + 2.5 * x))).0);
            add(timed!(libm::sinf(black_box(0.1 + 0.6 * x))).0);
            add(timed!(libm::cosf(black_box(0.4 + 2.5 * x))).0);
            add(timed!(libm::sqrtf(black_box(1.0 + 999.0 * x))).0);
            add(timed!(libm::hypotf(black_box(3.0 + x), black_box(40.0 * x))).0);
            add(timed!(poly.and_then(|p| p.eval(black_box(ratio), black_box(tc)))).0);
            let (t, op) = timed!(Operating::new(
                &TABLE2,
                MillingMode::Down,
                black_box(rr),
                black_box(tc)
            ));
            add(t);
            add(timed!(black_box(&op).slopes(&TABLE2, MillingMode::Down)).0);
            add(timed!(black_box(&op).force_scale_n(&TABLE2, &Tool::PAPER, black_box(tc))).0);
            add(timed!(invert(
                &TABLE2,
                MillingMode::Down,
                Ratio::Fxt,
                black_box(ratio),
                tc
            ))
            .0);
            // What the alarms evaluate for a threshold: eq. 7 at an engagement.
            add(timed!(
                Operating::new(&TABLE2, MillingMode::Down, black_box(rr), black_box(tc)).forces(
                    &TABLE2,
                    &Tool::PAPER,
                    black_box(tc),
                    black_box(1.0)
                )
            )
            .0);
            // The per-tooth conversions of the monitor, on the means of a tooth.
            let v = [black_box(360.0 + x), black_box(0.0)];
            add(timed!(black_box(&feed).feed_force_n(black_box([0.02 + x, 0.0]), v)).0);
            add(timed!(black_box(&feed).moving(v)).0);
            add(timed!(black_box(&spindle).tangential_force_n(
                black_box(0.4 + x),
                black_box(600.0),
                black_box(8.0)
            ))
            .0);
            add(timed!(estimator_core::fmath::hypot(
                black_box(3.0 + x),
                black_box(40.0 * x)
            ))
            .0);
        }
        let names = [
            "powf",
            "logf",
            "expf",
            "acosf",
            "sinf",
            "sinf_small",
            "cosf",
            "sqrtf",
            "hypotf",
            "poly_eval",
            "operating_new",
            "slopes",
            "force_scale",
            "invert",
            "eq7_forces",
            "feed_force",
            "feed_moving",
            "spindle_force",
            "fmath_hypot",
        ];
        for (stat, name) in s.iter().zip(names) {
            stat.write(w, name)?;
        }
        Ok(())
    }

    fn run() -> Result<(), ReplayError> {
        let (trace, _) = replay_monitor(TRACE)?;
        let monitor = monitor_config(trace.sample_rate_hz())
            .build()
            .map_err(ReplayError::Config)?;
        let mut st = Stats::default();
        let mut w = Buffered::stdout()?;
        writeln!(w, "{BEGIN}")?;
        // Case lines go through a counter, for the end line. Output is buffered and
        // flushed only outside the timed regions.
        let mut out = Counter { w: &mut w, n: 0 };
        calibrate(&mut out, &mut st)?;
        let c = run_trace(&monitor, &trace, &mut st)?;
        let peak = stack_peak();
        pieces(&mut out)?;
        for (s, name) in [
            (&st.overhead, "overhead"),
            (&st.sample, "sample"),
            (&st.tooth, "tooth"),
            (&st.tooth_est, "tooth_est"),
            (&st.tooth_est_poly, "tooth_est_poly"),
            (&st.tooth_est_inv, "tooth_est_inv"),
            (&st.tooth_flagged, "tooth_flagged"),
            (&st.est_poly, "est_poly"),
            (&st.est_auto_inv, "est_auto_inv"),
            (&st.est_inversion, "est_inversion"),
            (&st.alarm, "alarm"),
            (&st.alarm_est_poly, "alarm_est_poly"),
            (&st.alarm_flagged, "alarm_flagged"),
            (&st.alarm_wear, "alarm_wear"),
            (&st.pipe_sample, "pipe_sample"),
            (&st.pipe_tooth, "pipe_tooth"),
            (&st.pipe_tooth_poly, "pipe_tooth_poly"),
            (&st.pipe_tooth_inv, "pipe_tooth_inv"),
            (&st.pipe_tooth_flagged, "pipe_tooth_flagged"),
            (&st.probed_tooth_poly, "probed_tooth_poly"),
            (&st.stage_return, "stage_return"),
            (&st.probed_tooth_flagged, "probed_tooth_flagged"),
            (&st.stage_flagged_return, "stage_flagged_return"),
        ] {
            s.write(&mut out, name)?;
        }
        for (k, stage) in Stage::ALL.iter().enumerate() {
            // Names `stage_{stage}` and `stage_flagged_{stage}`: written in two parts, the
            // Stat line takes one word.
            let mut name = Name::default();
            write!(name, "stage_{}", stage.name())?;
            st.stage
                .get(k)
                .copied()
                .unwrap_or_default()
                .write(&mut out, name.as_str())?;
            let mut name = Name::default();
            write!(name, "stage_flagged_{}", stage.name())?;
            st.stage_flagged
                .get(k)
                .copied()
                .unwrap_or_default()
                .write(&mut out, name.as_str())?;
        }
        for (k, v) in [
            ("sample_rate_hz", trace.sample_rate_hz() as u32),
            ("samples", c.samples),
            ("records", c.records),
            ("records_valid", c.valid),
            ("records_estimated", c.estimated),
            ("estimates_polynomial", c.poly),
            ("estimates_inversion", c.inversion),
            ("estimate_rr_mismatch", c.rr_mismatch),
            ("pipeline_record_mismatch", c.pipeline_mismatch),
            ("alarm_output_mismatch", c.alarm_mismatch),
            ("probed_mismatch", c.probed_mismatch),
            ("alarm_events", c.alarm_events),
            ("wear_updates", c.wear_updates),
            ("blob_bytes", TRACE.len() as u32),
            ("monitor_bytes", core::mem::size_of::<Monitor>() as u32),
            ("pipeline_bytes", core::mem::size_of::<Pipeline>() as u32),
            (
                "pipeline_state_bytes",
                core::mem::size_of::<PipelineState>() as u32,
            ),
            (
                "monitor_state_bytes",
                core::mem::size_of::<MonitorState>() as u32,
            ),
            ("stack_peak_bytes", peak as u32),
        ] {
            writeln!(out, "info {k} {v}")?;
        }
        let n = out.n;
        writeln!(w, "{END_PREFIX}{n}")?;
        w.flush()?;
        Ok(())
    }

    /// A short string built with `write!` (stat names).
    #[derive(Default)]
    struct Name {
        buf: [u8; 32],
        len: usize,
    }

    impl Name {
        fn as_str(&self) -> &str {
            self.buf
                .get(..self.len)
                .and_then(|b| core::str::from_utf8(b).ok())
                .unwrap_or("?")
        }
    }

    impl Write for Name {
        fn write_str(&mut self, s: &str) -> fmt::Result {
            let end = self.len + s.len();
            self.buf
                .get_mut(self.len..end)
                .ok_or(fmt::Error)?
                .copy_from_slice(s.as_bytes());
            self.len = end;
            Ok(())
        }
    }

    /// Counts the lines written through it.
    struct Counter<'a, W: Write> {
        w: &'a mut W,
        n: u32,
    }

    impl<W: Write> Write for Counter<'_, W> {
        fn write_str(&mut self, s: &str) -> fmt::Result {
            self.n += s.bytes().filter(|&b| b == b'\n').count() as u32;
            self.w.write_str(s)
        }
    }

    #[entry]
    fn main() -> ! {
        let Some(mut cp) = cortex_m::Peripherals::take() else {
            eprint(format_args!(
                "icount-bench: core peripherals already taken\n"
            ));
            exit(false)
        };
        cp.SYST.set_clock_source(SystClkSource::Core);
        cp.SYST.set_reload(SYST_MASK);
        cp.SYST.clear_current();
        cp.SYST.enable_counter();
        paint_stack();
        match run() {
            Ok(()) => exit(true),
            Err(e) => {
                eprint(format_args!("icount-bench: {e}\n"));
                exit(false)
            }
        }
    }

    target_check::hardfault_exits!();
}

#[cfg(not(target_os = "none"))]
fn main() {}
