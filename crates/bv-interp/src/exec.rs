//! Running compiled functions: statements, calls, and the step, depth and
//! memory limits.
//!
//! A call's memory is one `Vec<f64>`: the module-scope variables at
//! addresses `0..globals`, then the frames of the calls in progress, each
//! right after its caller's. The vector is reused between calls on a thread.

use std::cell::Cell;

use crate::{
    InterpError, Limits,
    compile::{Arg, Func, Stmt},
    ins,
};

/// How a block ended.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Flow {
    Next,
    Break,
    Continue,
    Return,
}

thread_local! {
    /// The memory of the last call on this thread, kept for the next one.
    static MEMORY: Cell<Vec<f64>> = const { Cell::new(Vec::new()) };
}

/// Runs `body` with this thread's reusable memory.
pub(crate) fn with_memory<R>(body: impl FnOnce(&mut Vec<f64>) -> R) -> R {
    let mut mem = MEMORY.with(Cell::take);
    let r = body(&mut mem);
    // Do not keep a huge vector alive after an unusually large call.
    if mem.capacity() <= 1 << 20 {
        MEMORY.with(|m| m.set(mem));
    }
    r
}

/// The state of one call.
pub(crate) struct Machine<'p, 'm> {
    pub(crate) funcs: &'p [Func],
    pub(crate) mem: &'m mut Vec<f64>,
    pub(crate) steps: u64,
    pub(crate) depth: u32,
    pub(crate) limits: Limits,
}

impl<'p> Machine<'p, '_> {
    /// Pushes the frame of `f` at `fb`: checks the memory limit, then lays
    /// down the template (the cells after it are written before they are
    /// read).
    pub(crate) fn enter(&mut self, f: &Func, fb: usize) -> Result<(), InterpError> {
        let cells = match f.frame {
            Ok(c) => c as usize,
            Err(bytes) => {
                return Err(InterpError::Memory {
                    bytes: bytes.saturating_add(fb * 8),
                    limit: self.limits.max_memory_bytes,
                });
            }
        };
        let top = fb + cells;
        if top.saturating_mul(8) > self.limits.max_memory_bytes {
            return Err(InterpError::Memory {
                bytes: top * 8,
                limit: self.limits.max_memory_bytes,
            });
        }
        if self.mem.len() < top {
            self.mem.resize(top, 0.0);
        }
        let t = f.template.len();
        self.mem[fb..fb + t].copy_from_slice(&f.template);
        Ok(())
    }

    #[inline]
    fn tick(&mut self, n: u64) -> Result<(), InterpError> {
        self.steps += n;
        if self.steps > self.limits.max_steps {
            Err(InterpError::StepBudget {
                steps: self.limits.max_steps,
            })
        } else {
            Ok(())
        }
    }

    /// Runs the statements `body` of `f` in the frame at `fb`.
    pub(crate) fn block(
        &mut self,
        f: &'p Func,
        body: &'p [Stmt],
        fb: usize,
    ) -> Result<Flow, InterpError> {
        for s in body {
            self.tick(1)?;
            match *s {
                Stmt::Run(a, b, cost) => {
                    self.tick(cost)?;
                    ins::run(&f.ins[a as usize..b as usize], self.mem, fb);
                }
                Stmt::If {
                    cond,
                    ref accept,
                    ref reject,
                } => {
                    let branch = if self.mem[fb + cond as usize] != 0.0 {
                        accept
                    } else {
                        reject
                    };
                    match self.block(f, branch, fb)? {
                        Flow::Next => {}
                        other => return Ok(other),
                    }
                }
                Stmt::Switch {
                    selector,
                    ref cases,
                } => {
                    let v = self.mem[fb + selector as usize];
                    let start = cases
                        .iter()
                        .position(|c| c.value == Some(v))
                        .or_else(|| cases.iter().position(|c| c.value.is_none()));
                    if let Some(start) = start {
                        for c in &cases[start..] {
                            match self.block(f, &c.body, fb)? {
                                Flow::Next if c.fall_through => continue,
                                Flow::Next | Flow::Break => break,
                                // `continue` inside a switch continues the
                                // enclosing loop.
                                other => return Ok(other),
                            }
                        }
                    }
                }
                Stmt::Loop {
                    ref body,
                    ref continuing,
                    break_if,
                } => loop {
                    // Every iteration costs a step, so `loop {}` ends too.
                    self.tick(1)?;
                    match self.block(f, body, fb)? {
                        Flow::Break => break,
                        Flow::Return => return Ok(Flow::Return),
                        Flow::Next | Flow::Continue => {}
                    }
                    match self.block(f, continuing, fb)? {
                        Flow::Return => return Ok(Flow::Return),
                        Flow::Break => break,
                        Flow::Next | Flow::Continue => {}
                    }
                    if let Some(c) = break_if
                        && self.mem[fb + c as usize] != 0.0
                    {
                        break;
                    }
                },
                Stmt::Break => return Ok(Flow::Break),
                Stmt::Continue => return Ok(Flow::Continue),
                Stmt::Return(v) => {
                    if let Some((o, n)) = v {
                        self.tick(u64::from(n / 8))?;
                        ins::copy(self.mem, fb + o as usize, fb, n as usize);
                    }
                    return Ok(Flow::Return);
                }
                Stmt::Kill => return Err(InterpError::Kill),
                Stmt::Call {
                    func,
                    ref args,
                    result,
                } => self.call(f, func, args, result, fb)?,
            }
        }
        Ok(Flow::Next)
    }

    fn call(
        &mut self,
        caller: &Func,
        func: u32,
        args: &[Arg],
        result: Option<(u32, u32)>,
        fb: usize,
    ) -> Result<(), InterpError> {
        let funcs = self.funcs;
        let callee = funcs
            .get(func as usize)
            .ok_or_else(|| InterpError::Internal("call of a missing function".into()))?;
        if self.depth >= self.limits.max_call_depth {
            return Err(InterpError::CallDepth {
                depth: self.limits.max_call_depth,
            });
        }
        let nfb = fb + caller.frame.unwrap_or(0) as usize;
        // Laying down the frame and copying arguments cost like copies.
        let cells: u64 = args
            .iter()
            .map(|a| match *a {
                Arg::Val { n, .. } => u64::from(n),
                Arg::Ptr(_) => 1,
            })
            .sum::<u64>()
            + callee.template.len() as u64;
        self.tick(cells / 8)?;
        self.enter(callee, nfb)?;
        for (a, p) in args.iter().zip(callee.params.iter()) {
            let d = nfb + p.off as usize;
            match *a {
                Arg::Val { off, n } => ins::copy(self.mem, fb + off as usize, d, n as usize),
                Arg::Ptr(place) => self.mem[d] = place.addr(self.mem, fb) as f64,
            }
        }
        self.depth += 1;
        let r = self.block(callee, &callee.body, nfb);
        self.depth -= 1;
        r?;
        if let Some((o, n)) = result {
            ins::copy(self.mem, nfb, fb + o as usize, n as usize);
        }
        Ok(())
    }
}
