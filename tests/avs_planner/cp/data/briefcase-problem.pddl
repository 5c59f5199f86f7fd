(define (problem carry) (:domain briefcase)
  (:objects home office - place keys laptop - thing)
  (:init (at-case home) (at keys home) (at laptop home) (locked))
  (:goal (and (at keys office) (at laptop office) (at-case home) (not (in laptop)))))
