"""The exit status of every ``uvms-pin`` command (documented in docs/api.md, "Errors").

0 success; 2 bad input (nothing was run or written; but a metric of your own that fails
after a run: the run is kept, its metrics.json without yours); 3 a run stopped early (funnel
violation, divergence, the controller raised: its rollout is kept); 4 the system failed
(a full disk, a file removed meanwhile: the message names the file and what was kept);
130 Ctrl-C and 143 SIGTERM (what a run simulated is kept); 141 the reader of the output
went away (``| head``).
"""

EXIT_OK = 0
EXIT_BAD_INPUT = 2
EXIT_RUN_STOPPED = 3
EXIT_ENVIRONMENT = 4
EXIT_INTERRUPTED = 130  # as a shell reports a process stopped by Ctrl-C
EXIT_TERMINATED = 143  # as a shell reports a process SIGTERM ended (a batch time limit)
EXIT_BROKEN_PIPE = 141  # as a shell reports a process whose reader went away (| head)
