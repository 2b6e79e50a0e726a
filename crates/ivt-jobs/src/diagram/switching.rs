//! Branch switching of the diagram's search: at each located event of a
//! branch, the branches it leads to (both halves at a branch point, the
//! period-2 branch at a period doubling, the torus at a Neimark–Sacker point).

use super::*;

impl<P: PeriodicProblem> Search<'_, P> {
    /// Switches at every located event of branch `b` (below the depth
    /// bound); a failed switch is recorded, not an error.
    pub(super) fn switch_at_events(&mut self, b: usize) -> Result<(), HbError> {
        let (Some(Some((hb, _))), Some(events), Some(parent)) = (
            self.states.get(b).cloned(),
            self.located.get(b).cloned(),
            self.branches.get(b),
        ) else {
            return Ok(());
        };
        let level = parent.level;
        for (i, e) in events.iter().enumerate() {
            let Ok(bif) = &e.location else { continue };
            if e.kind == BifurcationKind::Fold
                || (e.kind == BifurcationKind::NeimarkSacker && !self.req.tori)
            {
                continue;
            }
            if level >= self.req.depth {
                self.search.events_beyond_depth += 1;
                continue;
            }
            let origin = Origin {
                kind: e.kind,
                omega: bif.lambda,
                event: Some(i),
            };
            let done = match e.kind {
                BifurcationKind::BranchPoint => {
                    self.switch_branch_point(b, &hb, bif, origin, level + 1)
                }
                BifurcationKind::PeriodDoubling => {
                    self.switch_period_doubling(b, &hb, bif, origin, level + 1)
                }
                _ => self.torus_at(b, &hb, bif, origin, level + 1),
            };
            if let Err(why) = done {
                self.search.failures.push(format!(
                    "{} at ω_f = {} on branch {b}: {why}",
                    e.kind.words(),
                    bif.lambda
                ));
            }
        }
        Ok(())
    }

    /// Both halves of the branch crossing at the branch point `bif`.
    fn switch_branch_point(
        &mut self,
        b: usize,
        hb: &HbOptions,
        bif: &Bifurcation,
        origin: Origin,
        level: usize,
    ) -> Result<(), HbError> {
        let mut branch = FamilyBranch::new(Frequency(self.problem), hb, bif.lambda)?;
        let d = new_direction(&mut branch, &bif.q, bif.lambda, &LocateOptions::default())?;
        let start = (bif.q.as_slice(), bif.lambda, d.as_slice());
        let from = (BranchKind::BranchPoint, Some(b), origin, level);
        self.both_halves(&mut branch, hb, start, from)
    }

    /// Both halves of the branch through `(q, ω_f)` stepped `±h` along the
    /// direction `d` (`h` the request's step relative to ‖q‖), each traced as
    /// `kind` from `parent` and `origin` at `level` unless already known.
    fn both_halves(
        &mut self,
        branch: &mut FamilyBranch<Frequency<'_, P>>,
        hb: &HbOptions,
        (q, omega, d): (&[f64], f64, &[f64]),
        (kind, parent, origin, level): (BranchKind, Option<usize>, Origin, usize),
    ) -> Result<(), HbError> {
        let opts = LocateOptions::default();
        let h = self.req.step * norm2(q).max(f64::MIN_POSITIVE);
        for side in [1.0, -1.0] {
            let (q1, w1) =
                switch_branch(branch, q, omega, d, side * h, &opts).map_err(trace_error)?;
            let mut x0 = q1;
            x0.push(w1);
            if self.known(hb, &x0, 0.25 * h) {
                self.search.duplicates += 1;
                continue;
            }
            self.trace(Pending {
                hb: hb.clone(),
                x0,
                direction: sign(w1 - omega),
                kind,
                parent,
                origin: Some(origin.clone()),
                level,
            })?;
        }
        Ok(())
    }

    /// The period-2 branch of the period doubling `bif`.
    fn switch_period_doubling(
        &mut self,
        b: usize,
        hb: &HbOptions,
        bif: &Bifurcation,
        origin: Origin,
        level: usize,
    ) -> Result<(), HbError> {
        let opts = LocateOptions::default();
        let h = self.req.step * norm2(&bif.q).max(f64::MIN_POSITIVE);
        let (branch, q1, w1) = period_doubled_start(Frequency(self.problem), hb, bif, h, &opts)
            .map_err(trace_error)?;
        let hb2 = branch.options().clone();
        let mut x0 = q1;
        x0.push(w1);
        if self.known(&hb2, &x0, 0.25 * h) {
            self.search.duplicates += 1;
            return Ok(());
        }
        self.trace(Pending {
            hb: hb2,
            x0,
            direction: sign(w1 - bif.lambda),
            kind: BranchKind::PeriodDoubling,
            parent: Some(b),
            origin: Some(origin),
            level,
        })?;
        Ok(())
    }

    /// The torus branch of the Neimark–Sacker point `bif` (its points read
    /// without error estimates).
    fn torus_at(
        &mut self,
        b: usize,
        hb: &HbOptions,
        bif: &Bifurcation,
        origin: Origin,
        level: usize,
    ) -> Result<(), HbError> {
        if !self.room() {
            return Ok(());
        }
        let ns = NeimarkSackerStart {
            coeffs: &bif.q,
            harmonics: hb.harmonics,
            lambda: bif.lambda,
            multipliers: &bif.multipliers,
        };
        let options = TorusOptions {
            subharmonic: hb.subharmonic,
            ..self.req.torus
        };
        let start = torus_start(
            Frequency(self.problem),
            &ns,
            &options,
            0.5 * self.req.step,
            &LocateOptions::default(),
        )?;
        let mut branch = start.branch;
        let lambda1 = start.first.last().copied().unwrap_or(f64::NAN);
        let mut copts = self.path.clone();
        copts.max_points = self.req.torus_points;
        let (path, termination) = crate::torus::follow(
            &mut branch,
            &start.first,
            sign(lambda1 - bif.lambda),
            &copts,
        )?;
        let mut points = Vec::with_capacity(path.len());
        for x in &path {
            let Some((&lambda, q)) = x.split_last() else {
                continue;
            };
            let m = branch.measures(q, lambda, 0)?;
            let exponent = branch.normal_exponent(q, lambda);
            points.push(DiagramPoint {
                omega: lambda,
                amplitude: m.amplitude_max,
                coeffs: Array(
                    q.get(..q.len().saturating_sub(1))
                        .unwrap_or_default()
                        .to_vec(),
                ),
                stable: exponent.map(|e| e < 0.0),
                stability: None,
                multipliers: None,
                rotation_number: Some(m.rotation_number),
                at: false,
            });
        }
        if termination == Termination::MaxPoints {
            self.search.truncated_branches += 1;
        }
        self.branches.push(DiagramBranch {
            kind: BranchKind::Torus,
            parent: Some(b),
            origin: Some(origin),
            level,
            harmonics: branch.harmonics().len(),
            subharmonic: hb.subharmonic,
            torus_harmonics: branch.harmonics().iter().map(|(a, k)| [a, k]).collect(),
            points,
            events: Vec::new(),
            termination,
        });
        self.search.deepest = self.search.deepest.max(level);
        self.states.push(None);
        self.located.push(Vec::new());
        Ok(())
    }

    /// Both halves of the branch through the fold `(q, ω_f)` with null vector
    /// `v` (stepped `±h` along it), unless known.
    pub(super) fn branches_from_fold(
        &mut self,
        q: &[f64],
        omega: f64,
        v: &[f64],
        origin: (Option<usize>, Origin),
    ) -> Result<(), HbError> {
        let hb = self.hb.clone();
        let mut branch = FamilyBranch::new(Frequency(self.problem), &hb, omega)?;
        let mut d = v.to_vec();
        d.push(0.0);
        let from = (BranchKind::FoldCurve, origin.0, origin.1, 0);
        self.both_halves(&mut branch, &hb, (q, omega, &d), from)
    }
}
